#!/usr/bin/env python3
"""Rewrites C++ calls of zwang's entry points written for the order before the one argument order
(docs/getting-started.md, "One argument order") in place:

    python3 docs/migration/argument_order.py FILE...

solveHybridDynamics, solveWithFriction and inverseDynamics(model, task, q, qd, x, ws[, options]) become
(model, ws, q, qd, x, task[, options]); jointSpaceInertia(model, q, ws) becomes (model, ws, q). framePose,
frameVelocity and frameAcceleration get the state (q; q, qd) of the nearest call before them in the same file
that computes kinematics, or Q_TODO / QD_TODO where there is none: check each (a wrong state is NotComputed at
run time, never a wrong value). Run it once per file: it does not recognise calls already in the new order.
The call sites of this repository were converted with it."""
import re, sys

ORDER = {  # old positions -> new order (indices into old args)
    'solveHybridDynamics': lambda a: [a[0], a[5], a[2], a[3], a[4], a[1]] if len(a) == 6 else None,
    'solveWithFriction': lambda a: ([a[0], a[5], a[2], a[3], a[4], a[1]] + a[6:]) if len(a) in (6, 7) else None,
    'inverseDynamics': lambda a: [a[0], a[5], a[2], a[3], a[4], a[1]] if len(a) == 6 else None,
    'jointSpaceInertia': lambda a: [a[0], a[2], a[1]] if len(a) == 3 else None,
    'problem::solve': lambda a: ([a[0], a[5], a[2], a[3], a[4], a[1]] + a[6:]) if len(a) in (6, 7) else None,
}
QUERIES = {'framePose': 4, 'frameVelocity': 5, 'frameAcceleration': 5}  # old arg counts
STATE_CALLS = ['solveHybridDynamics', 'solveWithFriction', 'inverseDynamics', 'jointSpaceInertia',
               'forwardKinematics', 'frameJacobian', 'problem::solve']

def split_args(text, start):
    """text[start] == '('; return (args, end index of ')')."""
    depth = 0; args = []; cur = start + 1; i = start
    in_str = None
    while i < len(text):
        ch = text[i]
        if in_str:
            if ch == '\\': i += 2; continue
            if ch == in_str: in_str = None
        elif ch in '"\'':
            in_str = ch
        elif ch in '([{':
            depth += 1
        elif ch in ')]}':
            depth -= 1
            if depth == 0:
                args.append(text[cur:i]); return args, i
        elif ch == ',' and depth == 1:
            args.append(text[cur:i]); cur = i + 1
        i += 1
    raise ValueError('unbalanced')

def calls(text, names):
    pat = re.compile(r'(?<![\w.>])((?:zwang::)?(' + '|'.join(re.escape(n) for n in names) + r'))\s*\(')
    for m in pat.finditer(text):
        # skip declarations/definitions: 'Status name(' or preceding type
        before = text[max(0, m.start() - 40):m.start()]
        yield m

def is_decl(args):
    return any(re.search(r'\b(const\s+)?(Model|Task|Workspace)\s*&', a) for a in args)

def rewrite(text):
    # pass 1: reorder algorithm calls
    out = []; pos = 0; edits = []
    for m in calls(text, list(ORDER)):
        name = m.group(2)
        try: args, end = split_args(text, m.end() - 1)
        except ValueError: continue
        if is_decl(args): continue
        new = ORDER[name]([a.strip() for a in args])
        if new is None: print('skip', name, len(args), file=sys.stderr); continue
        edits.append((m.end(), end, ', '.join(new)))
    for s, e, r in reversed(edits):
        text = text[:s] + r + text[e:]
    # pass 2: queries take the state of the preceding state call
    state_pos = []
    for m in calls(text, STATE_CALLS):
        try: args, end = split_args(text, m.end() - 1)
        except ValueError: continue
        if is_decl(args): continue
        a = [x.strip() for x in args]
        name = m.group(2)
        q = a[2] if len(a) > 2 else None
        qd = a[3] if name not in ('jointSpaceInertia', 'frameJacobian') and len(a) > 3 else None
        state_pos.append((m.start(), q, qd))
    edits = []
    for m in calls(text, list(QUERIES)):
        name = m.group(2)
        try: args, end = split_args(text, m.end() - 1)
        except ValueError: continue
        if is_decl(args) or len(args) != QUERIES[name]:
            if not is_decl(args): print('skip query', name, len(args), file=sys.stderr)
            continue
        prev = [sp for sp in state_pos if sp[0] < m.start()]
        q, qd = (prev[-1][1], prev[-1][2]) if prev else ('Q_TODO', 'QD_TODO')
        if q is None: q = 'Q_TODO'
        if qd is None: qd = 'QD_TODO'
        a = [x.strip() for x in args]
        state = [q] if name == 'framePose' else [q, qd]
        edits.append((m.end(), end, ', '.join(a[:2] + state + a[2:])))
    for s, e, r in reversed(edits):
        text = text[:s] + r + text[e:]
    return text

for path in sys.argv[1:]:
    t = open(path).read()
    n = rewrite(t)
    if n != t:
        open(path, 'w').write(n); print('rewrote', path)
