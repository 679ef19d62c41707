#!/usr/bin/env python3
"""No function over 80 lines in the given folders of src/ (issue #26): a long
function is split into named stages. A function is counted from the first line
of its signature (at column 0, as clang-format leaves it) to its closing brace
at column 0, lambdas inside it included. Exits 1 naming every one over the limit."""
import pathlib
import re
import sys

LIMIT = 80
root = pathlib.Path(sys.argv[1])
folders = sys.argv[2:]
start = re.compile(r"^[A-Za-z_].*\(")  # a signature's first line
not_a_function = re.compile(r"^(namespace|struct|class|enum|using|static_assert|template|#)")
long_ones = []
for folder in folders:
    for path in sorted((root / "src" / folder).glob("*.cpp")):
        first = None
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if first is None:
                if start.match(line) and not not_a_function.match(line) and not line.rstrip().endswith((";", "}")):
                    first, name = number, line.strip()
            elif line.startswith("}"):
                if number - first + 1 > LIMIT:
                    long_ones.append(f"{path.relative_to(root)}:{first}: {number - first + 1} lines: {name[:70]}")
                first = None
print("\n".join(long_ones) if long_ones else f"functions: none over {LIMIT} lines in src/{{{','.join(folders)}}}")
sys.exit(1 if long_ones else 0)
