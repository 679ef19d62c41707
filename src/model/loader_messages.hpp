// The model loaders' messages, shared by the URDF loader (urdf.cpp) and the MJCF loader (src/mujoco/mjcf.cpp) so
// that both spell numbers, name lists, their source and a file that cannot be read alike (not installed).
#pragma once

#include <cerrno>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "zwang/model.hpp"

namespace zwang::internal {

// A number as messages show it: 12 significant digits.
inline std::string fmt(double value) {
  std::ostringstream out;
  out << std::setprecision(12) << value;
  return out.str();
}

// 'a', 'b', … (n more): at most max_shown names.
inline std::string nameList(const std::vector<std::string>& names, std::size_t max_shown = 12) {
  std::ostringstream out;
  for (std::size_t k = 0; k < names.size() && k < max_shown; ++k) out << (k ? ", " : "") << "'" << names[k] << "'";
  if (names.size() > max_shown) out << ", … (" << names.size() - max_shown << " more)";
  return out.str();
}

// Everything a loader throws goes through here: "<source>: <what>".
class Reporter {
 public:
  explicit Reporter(std::string source) : source_(std::move(source)) {}
  [[noreturn]] void fail(const std::string& what) const { throw ModelError(source_ + ": " + what); }
  const std::string& source() const { return source_; }

  // The source as a file opened for reading; fails naming why it cannot be (a directory, errno's reason).
  std::ifstream open() const {
    std::error_code ec;
    if (std::filesystem::is_directory(source_, ec)) fail("cannot read the file: it is a directory");
    std::ifstream in(source_, std::ios::binary);
    if (!in) {
      const int err = errno;
      fail(std::string("cannot open the file (") + (err ? std::strerror(err) : "unknown error") + ")");
    }
    return in;
  }

  // Runs a ModelBuilder call and prefixes its errors with the source.
  template <class F>
  void builder(F&& call) const {
    try {
      call();
    } catch (const ModelError& e) {
      fail(e.what());
    }
  }

 private:
  std::string source_;
};

}  // namespace zwang::internal
