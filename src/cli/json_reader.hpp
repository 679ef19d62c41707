// Reading JSON input with errors that name the file and the JSON path
// (e.g. "constraints[1].directions[2]").
//
// parseJson does not recurse (nlohmann's SAX parser keeps its own stack) and
// refuses nesting deeper than kMaxJsonDepth, duplicate keys and numbers that
// overflow a double; JsonReader checks types, lengths, ranges and key sets.
#pragma once

#include <Eigen/Core>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>

namespace zwang::cli {

using Json = nlohmann::ordered_json;  // keeps the file's key order

constexpr std::size_t kMaxJsonDepth = 64;          // a problem needs 5
constexpr double kMaxMagnitude = 1e12;             // larger numbers are refused ("huge")
constexpr std::size_t kMaxInputBytes = 64u << 20;  // 64 MiB

// "a" + "b" → "a.b"; "" + "b" → "b"; "a" + 3 → "a[3]".
std::string childPath(const std::string& path, const std::string& key);
std::string childPath(const std::string& path, std::size_t index);

// Parse JSON text (comments allowed). CliError "FILE: line L, column C: ..."
// for malformed text, "FILE: PATH: ..." for the checks above.
Json parseJson(const std::string& text, const std::string& file);

class JsonReader {
 public:
  explicit JsonReader(std::string file) : file_(std::move(file)) {}
  const std::string& file() const { return file_; }

  // Throws CliError(1, "FILE: PATH: what") ("FILE: what" for the root).
  [[noreturn]] void fail(const std::string& path, const std::string& what) const;

  // An object whose keys are all in `allowed` (an unknown key is an error
  // naming its path and the allowed keys).
  const Json& object(const Json& value, const std::string& path, std::initializer_list<const char*> allowed) const;
  const Json& array(const Json& value, const std::string& path) const;
  // A finite number with |x| ≤ kMaxMagnitude.
  double number(const Json& value, const std::string& path) const;
  bool boolean(const Json& value, const std::string& path) const;
  std::string string(const Json& value, const std::string& path) const;
  // An array of numbers; `expected` < 0: any length, else exactly that many
  // (`expected_what` says what the count is, e.g. "one per direction").
  Eigen::VectorXd numbers(const Json& value, const std::string& path, long expected = -1,
                          const std::string& expected_what = "") const;

 private:
  std::string file_;
};

// "a string (\"abc\")", "an array", ... for messages.
std::string describe(const Json& value);
// A number for messages: shortest round-trip form.
std::string formatNumber(double value);

}  // namespace zwang::cli
