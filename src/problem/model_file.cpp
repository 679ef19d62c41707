// The choice of loader by the model file's name, once for both front ends (problem.hpp, loadModelFile). MuJoCo
// is optional: the MJCF loader is linked only when zwang_mujoco is built (ZWANG_HAVE_MUJOCO, src/problem's
// CMakeLists.txt); without it an MJCF file is refused with the reason.
#include <algorithm>
#include <cctype>

#include "problem.hpp"
#ifdef ZWANG_HAVE_MUJOCO
#include "zwang/mjcf.hpp"
#endif

namespace zwang::problem {

bool isMjcfPath(const std::string& path) {
  if (path.size() < 4) return false;
  std::string end = path.substr(path.size() - 4);
  std::transform(end.begin(), end.end(), end.begin(), [](unsigned char c) { return std::tolower(c); });
  return end == ".xml";
}

LoadedModel loadMjcf(const std::string& source, bool from_string, bool strict) {
#ifdef ZWANG_HAVE_MUJOCO
  MjcfOptions options;
  options.strict = strict;
  MjcfModel loaded = from_string ? readMjcfString(source, options) : readMjcfFile(source, options);
  return {std::move(loaded.model), loaded.gravity};
#else
  (void)strict;
  throw ModelError((from_string ? std::string("<string>") : source) +
                   ": MJCF needs zwang built with MuJoCo (Debian: libmujoco-dev; CMake option ZWANG_WITH_MUJOCO)");
#endif
}

namespace {

// The URDF options that mean nothing for an MJCF file, as the front end spells them; empty when none is set.
std::string urdfOnlyOption(const internal::NamedUrdfOptions& options) {
  if (!options.root.empty()) return "the root link";
  if (!options.tip.empty()) return options.names.tip;
  if (!options.rotor_inertia.empty()) return options.names.rotor_inertia;
  if (options.attach_beyond_tip) return options.names.attach_beyond_tip;
  if (options.mimic == MimicJoints::Lock) return options.names.lock_mimic;
  if (options.mimic == MimicJoints::Refuse) return options.names.refuse_mimic;
  return "";
}

}  // namespace

LoadedModel loadModelFile(const std::string& path, const internal::NamedUrdfOptions& options) {
  if (!isMjcfPath(path)) return {internal::loadUrdfFile(path, options), std::nullopt};
  const std::string option = urdfOnlyOption(options);
  if (!option.empty())
    throw ModelError(path + ": " + option + " applies to URDF models only (an MJCF model loads whole, docs/mujoco.md)");
  LoadedModel loaded = loadMjcf(path, false, options.strict);
  if (options.base != BaseType::Fixed && (!options.base_may_match_file || loaded.model.baseType() != options.base))
    throw ModelError(path + ": " + options.names.base + " " + toString(options.base) + ": the MJCF model's base is " +
                     toString(loaded.model.baseType()) + " (an MJCF model's base is its own: a free joint on the " +
                     "world's only child body)");
  return loaded;
}

}  // namespace zwang::problem
