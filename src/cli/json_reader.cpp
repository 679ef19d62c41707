// Path-tracking JSON parsing and checked access (see json_reader.hpp).
#include "json_reader.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "cli.hpp"

namespace zwang::cli {

std::string childPath(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }

std::string childPath(const std::string& path, std::size_t index) { return path + "[" + std::to_string(index) + "]"; }

std::string formatNumber(double value) {
  char buffer[40];
  for (int precision = 1; precision <= 17; ++precision) {  // the shortest form that reads back exactly
    std::snprintf(buffer, sizeof buffer, "%.*g", precision, value);
    if (std::strtod(buffer, nullptr) == value) break;
  }
  return buffer;
}

std::string describe(const Json& value) {
  switch (value.type()) {
    case Json::value_t::null: return "null";
    case Json::value_t::object: return "an object";
    case Json::value_t::array: return "an array";
    case Json::value_t::string: return "a string (" + printable(value.dump(), 40) + ")";
    case Json::value_t::boolean: return value.get<bool>() ? "true" : "false";
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float: return "a number (" + value.dump() + ")";
    default: return "a " + std::string(value.type_name());
  }
}

namespace {

// Builds the document through nlohmann's non-recursive SAX interface,
// tracking the JSON path of every value, so that deep nesting, duplicate keys
// and overflowing numbers are reported with their place.
class Builder {
 public:
  using number_integer_t = Json::number_integer_t;
  using number_unsigned_t = Json::number_unsigned_t;
  using number_float_t = Json::number_float_t;
  using string_t = Json::string_t;
  using binary_t = Json::binary_t;

  Json root;
  std::string error;  // set when parsing stopped

  bool null() { return put(Json(nullptr), false); }
  bool boolean(bool value) { return put(Json(value), false); }
  bool number_integer(number_integer_t value) { return put(Json(value), false); }
  bool number_unsigned(number_unsigned_t value) { return put(Json(value), false); }
  bool number_float(number_float_t value, const string_t& text) {
    if (!std::isfinite(value)) return stop(where(), "the number " + printable(text, 40) + " is out of range");
    return put(Json(value), false);
  }
  bool string(string_t& value) { return put(Json(std::move(value)), false); }
  bool binary(binary_t&) { return stop(where(), "binary values are not JSON"); }
  bool start_object(std::size_t) { return open(Json::object()); }
  bool start_array(std::size_t) { return open(Json::array()); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }
  bool key(string_t& name) {
    Json* object = stack_.back();
    if (object->contains(name)) return stop(childPath(path(), name), "duplicate key");
    keys_.back() = name;
    return true;
  }
  bool parse_error(std::size_t position, const std::string&, const nlohmann::detail::exception& e) {
    // nlohmann: "[json.exception.parse_error.101] parse error at line 1, column 2: syntax error ..." or
    // "[json.exception.out_of_range.406] number overflow parsing '1e400'". Keep what follows the
    // location, and say where ourselves: line and column (and for an overflow the value's JSON path).
    std::string what = e.what();
    if (const auto bracket = what.find("] "); bracket != std::string::npos) what = what.substr(bracket + 2);
    if (what.rfind("parse error", 0) == 0)
      if (const auto colon = what.find(": "); colon != std::string::npos) what = what.substr(colon + 2);
    const bool overflow = e.id == 406;  // number overflow: a fault of the value being read
    if (overflow) {
      const auto quote = what.find('\'');
      what = "the number " + (quote == std::string::npos ? std::string("") : printable(what.substr(quote), 40)) +
             " is out of range (not finite as a double)";
    }
    std::size_t line = 1, line_start = 0;
    for (std::size_t k = 0; k < position && k < text_.size(); ++k)
      if (text_[k] == '\n') {
        ++line;
        line_start = k + 1;
      }
    const std::string location =
        "line " + std::to_string(line) + ", column " + std::to_string(position - std::min(position, line_start));
    // A syntax error is a fault of the text, not of a value: the key last read
    // may be long complete (`{"model": "a.urdf" "q": …}`), so no JSON path.
    return stop(overflow ? where() : "", location + ": " + what);
  }
  explicit Builder(const std::string& text) : text_(text) {}

 private:
  const std::string& text_;
  std::vector<Json*> stack_;       // the open containers, outermost first
  std::vector<std::string> keys_;  // per open container: the key of the value being read (objects)

  // The path of the innermost open container.
  std::string path() const {
    std::string p;
    for (std::size_t level = 1; level < stack_.size(); ++level) {
      const Json* parent = stack_[level - 1];
      p = parent->is_array() ? childPath(p, parent->size() - 1) : childPath(p, keys_[level - 1]);
    }
    return p;
  }
  // The path of the value about to be added.
  std::string where() const {
    if (stack_.empty()) return "";
    const Json* parent = stack_.back();
    return parent->is_array() ? childPath(path(), parent->size()) : childPath(path(), keys_.back());
  }
  bool stop(const std::string& at, const std::string& what) {
    error = at.empty() ? what : (at.size() > 120 ? printable(at, 120) : at) + ": " + what;
    return false;
  }
  bool put(Json value, bool container) {
    Json* slot = &root;
    if (!stack_.empty()) {
      Json* parent = stack_.back();
      if (parent->is_array()) {
        parent->push_back(std::move(value));
        slot = &parent->back();
      } else {
        slot = &(*parent)[keys_.back()];
        *slot = std::move(value);
      }
    } else {
      root = std::move(value);
    }
    if (container) {  // no value is added to the parent while this one is open: the pointer stays valid
      stack_.push_back(slot);
      keys_.emplace_back();
    }
    return true;
  }
  bool open(Json container) {
    if (stack_.size() >= kMaxJsonDepth)
      return stop(where(), "nested deeper than " + std::to_string(kMaxJsonDepth) + " levels of arrays and objects");
    return put(std::move(container), true);
  }
  bool close() {
    stack_.pop_back();
    keys_.pop_back();
    return true;
  }
};

}  // namespace

Json parseJson(const std::string& text, const std::string& file) {
  Builder builder(text);
  const bool ok = Json::sax_parse(text, &builder, nlohmann::detail::input_format_t::json, /*strict=*/true,
                                  /*ignore_comments=*/true);
  if (!ok) throw CliError(kExitError, file + ": " + (builder.error.empty() ? "invalid JSON" : builder.error));
  return std::move(builder.root);
}

void JsonReader::fail(const std::string& path, const std::string& what) const {
  throw CliError(kExitError, file_ + ": " + (path.empty() ? what : path + ": " + what));
}

const Json& JsonReader::object(const Json& value, const std::string& path,
                               std::initializer_list<const char*> allowed) const {
  if (!value.is_object()) fail(path, "expected an object, got " + describe(value));
  for (const auto& item : value.items()) {
    bool known = false;
    for (const char* name : allowed) known = known || item.key() == name;
    if (!known) {
      std::string list;
      for (const char* name : allowed) list += (list.empty() ? "" : ", ") + std::string(name);
      fail(childPath(path, printable(item.key(), 60)), "unknown key (allowed here: " + list + ")");
    }
  }
  return value;
}

const Json& JsonReader::array(const Json& value, const std::string& path) const {
  if (!value.is_array()) fail(path, "expected an array, got " + describe(value));
  return value;
}

double JsonReader::number(const Json& value, const std::string& path) const {
  if (!value.is_number()) fail(path, "expected a number, got " + describe(value));
  const double x = value.get<double>();
  if (!std::isfinite(x)) fail(path, "the number is not finite");
  if (std::abs(x) > kMaxMagnitude)
    fail(path, "the number " + formatNumber(x) + " is too large (|x| must be at most 1e12)");
  return x;
}

bool JsonReader::boolean(const Json& value, const std::string& path) const {
  if (!value.is_boolean()) fail(path, "expected true or false, got " + describe(value));
  return value.get<bool>();
}

std::string JsonReader::string(const Json& value, const std::string& path) const {
  if (!value.is_string()) fail(path, "expected a string, got " + describe(value));
  return value.get<std::string>();
}

Eigen::VectorXd JsonReader::numbers(const Json& value, const std::string& path, long expected,
                                    const std::string& expected_what) const {
  array(value, path);
  const auto count = static_cast<long>(value.size());
  if (expected >= 0 && count != expected)
    fail(path, "has " + std::to_string(count) + (count == 1 ? " entry" : " entries") + ", expected " +
                   std::to_string(expected) + (expected_what.empty() ? "" : " (" + expected_what + ")"));
  Eigen::VectorXd out(count);
  for (std::size_t k = 0; k < value.size(); ++k)
    out[static_cast<Eigen::Index>(k)] = number(value[k], childPath(path, k));
  return out;
}

}  // namespace zwang::cli
