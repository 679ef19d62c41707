// libFuzzer target: the MJCF loader (readMjcfString, through MuJoCo's mj_loadXML).
//
// Two modes, chosen by the first byte:
//  * '<': the bytes are the MJCF text as they are (the seed corpus's files,
//    mutated byte-wise with mjcf.dict's tokens);
//  * anything else: the bytes drive a generator of MJCF documents (a tree of
//    up to 8 bodies with hinge, slide, ball and free joints, anchors, axes,
//    orientations in every MJCF spelling, ranges, limited, ref, armature,
//    frictionloss, damping, stiffness, inertials or geoms, sites, joint
//    equalities with any polycoef, tendons, actuators, <compiler> angle and
//    inertia settings, <option> gravity and flags), whose numbers are ordinary,
//    zero, negative, huge, tiny, or not numbers at all ("nan", "inf", "1e400",
//    "", "x"): MuJoCo's XML parser sees well-formed documents and its compiler
//    and zwang's reading of the compiled model do the work.
//
// Fails (abort) when the loader lets anything but a ModelError with a message
// out, when a model that loads carries a non-finite number (an inertia, a
// placement, an axis, friction, a mimic law, the gravity), when strict mode
// does not refuse exactly the models that have warnings (generated documents), and when the
// loaded model, solved at its neutral configuration at rest and at a random
// state (plain, forward and friction-aware dynamics, with the file's
// gravity), returns an undocumented status, NonFinite for finite inputs, or
// non-finite outputs with Ok.
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "fuzz_common.hpp"
#include "zwang/mjcf.hpp"
#include "zwang/zwang.hpp"

namespace {

using namespace zwang;

// ---------------------------------------------------------------------------
// The generator

// Per document: 0, every number ordinary; else one number in `awkward_one_in` is an awkward one (most documents
// should compile, so that zwang's reading and the solves are reached).
int awkward_one_in = 0;

// A number as MJCF text: ordinary (uniform in [lo, hi]), or zero, any double, or not a number at all.
std::string number(FuzzedDataProvider& in, double lo, double hi) {
  static const char* const kSpecial[] = {"0",      "-0",   "1",   "-1",   "1e-300", "1e300", "-1e300",  "1e400",
                                         "-1e400", "nan",  "NaN", "-nan", "inf",    "-inf",  "1e-12",   "-1e-12",
                                         "1e12",   "1e15", "",    "x",    "1e",     "0x10",  "4.9e-324"};
  char text[32];
  if (awkward_one_in > 0 && in.ConsumeIntegralInRange(1, awkward_one_in) == 1) {
    switch (in.ConsumeIntegralInRange(0, 2)) {
      case 0: return kSpecial[in.ConsumeIntegralInRange<std::size_t>(0, std::size(kSpecial) - 1)];
      case 1: std::snprintf(text, sizeof text, "%.17g", in.ConsumeFloatingPoint<double>()); return text;
      default: return "0";
    }
  }
  std::snprintf(text, sizeof text, "%.6g", in.ConsumeFloatingPointInRange(lo, hi));
  return text;
}

std::string numbers(FuzzedDataProvider& in, int count, double lo, double hi) {
  std::string out;
  for (int k = 0; k < count; ++k) out += (k ? " " : "") + number(in, lo, hi);
  return out;
}

std::string attr(const char* name, const std::string& value) { return std::string(" ") + name + "=\"" + value + "\""; }

template <std::size_t N>
const char* pick(FuzzedDataProvider& in, const char* const (&options)[N]) {
  return options[in.ConsumeIntegralInRange<std::size_t>(0, N - 1)];
}

// An orientation in one of MJCF's spellings (none: the identity), degenerate ones included.
std::string orientation(FuzzedDataProvider& in) {
  switch (in.ConsumeIntegralInRange(0, 7)) {
    case 0: return attr("quat", numbers(in, 4, -1.0, 1.0));
    case 1:
      if (awkward_one_in == 0) return "";
      return attr("quat", pick(in, {"0 0 0 0", "1e-200 0 0 0", "1e-200 1e-200 0 0", "-1 0 0 0", "1 1 1 1"}));
    case 2: return attr("euler", numbers(in, 3, -360.0, 360.0));
    case 3: return attr("axisangle", numbers(in, 4, -2.0, 2.0));
    case 4: return attr("xyaxes", numbers(in, 6, -1.0, 1.0));
    case 5: return attr("zaxis", numbers(in, 3, -1.0, 1.0));
    default: return "";
  }
}

struct Generator {
  explicit Generator(FuzzedDataProvider& input) : in(input) {}
  FuzzedDataProvider& in;
  int bodies = 0, joints = 0, sites = 0;
  std::string xml;

  std::string jointName(int k) const { return "j" + std::to_string(k); }

  void joint(bool world_child) {
    static const char* const kTypes[] = {"hinge", "hinge", "slide", "ball", "free", ""};
    const char* type = kTypes[in.ConsumeIntegralInRange<std::size_t>(0, world_child ? 5 : 3)];
    if (!world_child && in.ConsumeProbability<double>() < 0.05) type = "free";  // refused below the world's children
    xml += "<joint";
    if (in.ConsumeProbability<double>() < 0.95)  // else unnamed, or a name given twice
      xml += attr("name", in.ConsumeProbability<double>() < 0.97 ? jointName(joints) : jointName(0));
    ++joints;
    if (type[0]) xml += attr("type", type);
    if (in.ConsumeBool()) xml += attr("pos", numbers(in, 3, -1.0, 1.0));
    if (in.ConsumeBool()) xml += attr("axis", numbers(in, 3, -1.0, 1.0));
    // MuJoCo refuses a ball joint's range (but (0, r)), a range without `limited` and `limited` without a range
    const bool range = in.ConsumeBool() && (std::string(type) != "ball" || awkward_one_in > 0);
    if (range) xml += attr("range", number(in, -180.0, -0.01) + " " + number(in, 0.01, 180.0));
    if (range || (awkward_one_in > 0 && in.ConsumeProbability<double>() < 0.1))
      xml += attr("limited", in.ConsumeProbability<double>() < 0.97 ? pick(in, {"true", "false"})
                                                                    : pick(in, {"auto", "1", "maybe"}));
    if (in.ConsumeProbability<double>() < 0.2) xml += attr("ref", number(in, -90.0, 90.0));
    if (in.ConsumeProbability<double>() < 0.3) xml += attr("armature", number(in, 0.0, 1.0));
    if (in.ConsumeProbability<double>() < 0.3) xml += attr("frictionloss", number(in, 0.0, 10.0));
    if (in.ConsumeProbability<double>() < 0.3) xml += attr("damping", number(in, 0.0, 10.0));
    if (in.ConsumeProbability<double>() < 0.1) xml += attr("stiffness", number(in, 0.0, 100.0));
    xml += "/>";
  }

  // Principal moments (a, b, c) that meet MuJoCo's triangle inequality: each is the sum of two of three second moments.
  std::string moments() {
    const double s1 = in.ConsumeFloatingPointInRange(0.01, 1.0), s2 = in.ConsumeFloatingPointInRange(0.01, 1.0),
                 s3 = in.ConsumeFloatingPointInRange(0.01, 1.0);
    char text[96];
    std::snprintf(text, sizeof text, "%.6g %.6g %.6g", s2 + s3, s1 + s3, s1 + s2);
    return text;
  }

  void mass() {
    const int kind = in.ConsumeIntegralInRange(0, 9);
    if (kind <= 5) {
      xml += "<inertial" + attr("pos", numbers(in, 3, -1.0, 1.0)) + attr("mass", number(in, 0.01, 10.0));
      if (in.ConsumeBool())  // MuJoCo takes an orientation with diaginertia only
        xml += attr("diaginertia", awkward_one_in > 0 && in.ConsumeBool() ? numbers(in, 3, 0.0, 1.0) : moments()) +
               orientation(in);
      else  // diagonal dominant: positive definite, within the triangle inequality
        xml += attr("fullinertia", numbers(in, 3, 1.0, 1.3) + " " + numbers(in, 3, -0.1, 0.1));
      xml += "/>";
    } else if (kind <= 8) {
      static const char* const kShapes[] = {"sphere", "box", "capsule", "cylinder", "ellipsoid"};
      if (in.ConsumeBool()) {
        xml += "<geom" + attr("type", pick(in, kShapes)) +
               attr("size", numbers(in, in.ConsumeIntegralInRange(1, 3), 0.01, 1.0));
      } else {
        xml += "<geom" + attr("type", pick(in, {"capsule", "cylinder"})) + attr("fromto", numbers(in, 6, -1.0, 1.0)) +
               attr("size", number(in, 0.01, 0.5));
      }
      if (in.ConsumeBool()) xml += attr(in.ConsumeBool() ? "mass" : "density", number(in, 0.01, 1000.0));
      xml += "/>";
    }  // else no mass at all
  }

  void body(int depth, bool world_child) {
    const int id = ++bodies;
    xml += "<body";
    if (in.ConsumeProbability<double>() < 0.95) xml += attr("name", "b" + std::to_string(id));
    if (in.ConsumeBool()) xml += attr("pos", numbers(in, 3, -1.0, 1.0));
    xml += orientation(in) + ">";
    const int count = in.ConsumeIntegralInRange(0, 9);
    const int joint_count = count <= 6 ? 1 : count - 6;  // 0–3 joints, mostly one (one when the bytes run out)
    for (int k = 0; k < joint_count; ++k) joint(world_child);
    mass();
    for (int k = 0; k < 3 && in.remaining_bytes() > 0 && in.ConsumeProbability<double>() < 0.2; ++k) {
      xml += "<site" + attr("name", in.ConsumeProbability<double>() < 0.9 ? "s" + std::to_string(sites++)
                                                                          : "b" + std::to_string(id));
      xml += attr("pos", numbers(in, 3, -1.0, 1.0)) + orientation(in) + "/>";
    }
    while (bodies < 8 && depth < 6 && in.remaining_bytes() > 0 && in.ConsumeProbability<double>() < 0.6)
      body(depth + 1, false);
    xml += "</body>";
  }

  void equalities() {
    if (joints == 0 || in.ConsumeProbability<double>() < 0.7) return;
    xml += "<equality>";
    for (int e = in.ConsumeIntegralInRange(1, 3); e > 0; --e) {
      const int kind = in.ConsumeIntegralInRange(0, 9);
      if (kind <= 7) {
        const int first = in.ConsumeIntegralInRange(0, joints - 1);
        xml += "<joint" + attr("joint1", jointName(first));
        if (kind <= 6 && joints > 1)  // another joint (MuJoCo refuses a joint equal to itself)
          xml += attr("joint2", jointName((first + in.ConsumeIntegralInRange(1, joints - 1)) % joints));
        if (in.ConsumeBool()) {
          const bool degree1 = in.ConsumeBool();
          xml += attr("polycoef", numbers(in, 2, -2.0, 2.0) + (degree1 ? " 0 0 0" : " " + numbers(in, 3, -1.0, 1.0)));
        }
        if (in.ConsumeProbability<double>() < 0.2) xml += attr("active", pick(in, {"false", "true"}));
        xml += "/>";
      } else {
        xml += std::string(kind == 8 ? "<connect" : "<weld") + attr("body1", "b1");
        if (bodies > 1) xml += attr("body2", "b" + std::to_string(in.ConsumeIntegralInRange(2, bodies)));
        if (kind == 8) xml += attr("anchor", numbers(in, 3, -1.0, 1.0));
        xml += "/>";
      }
    }
    xml += "</equality>";
  }

  std::string document() {
    static const int kAwkward[] = {0, 0, 0, 4, 16, 64};
    awkward_one_in = kAwkward[in.ConsumeIntegralInRange<std::size_t>(0, std::size(kAwkward) - 1)];
    xml = "<mujoco model=\"fuzz\"><compiler";
    if (in.ConsumeBool()) xml += attr("angle", pick(in, {"degree", "radian"}));
    if (in.ConsumeBool()) xml += attr("inertiafromgeom", pick(in, {"false", "true", "auto"}));
    if (in.ConsumeProbability<double>() < 0.1) xml += attr("eulerseq", pick(in, {"xyz", "zyx", "XYZ", "xyx"}));
    if (in.ConsumeProbability<double>() < 0.1) xml += attr("boundmass", number(in, 0.0, 1.0));
    if (in.ConsumeProbability<double>() < 0.1) xml += attr("boundinertia", number(in, 0.0, 1.0));
    if (in.ConsumeProbability<double>() < 0.1) xml += attr("balanceinertia", pick(in, {"true", "false"}));
    if (in.ConsumeProbability<double>() < 0.1) xml += attr("settotalmass", number(in, -1.0, 100.0));
    xml += "/><option";
    if (in.ConsumeBool()) xml += attr("gravity", numbers(in, 3, -20.0, 20.0));
    xml += ">";
    if (in.ConsumeProbability<double>() < 0.2) {
      static const char* const kFlags[] = {"gravity", "limit", "frictionloss", "passive", "equality", "constraint"};
      xml += "<flag" + attr(pick(in, kFlags), pick(in, {"disable", "enable"})) + "/>";
    }
    xml += "</option>";
    if (in.ConsumeProbability<double>() < 0.2) {
      xml += "<default><joint";
      if (in.ConsumeBool()) xml += attr("armature", number(in, 0.0, 1.0));
      if (in.ConsumeBool()) xml += attr("frictionloss", number(in, 0.0, 1.0));
      if (in.ConsumeBool()) xml += attr("damping", number(in, 0.0, 1.0));
      if (in.ConsumeBool()) xml += attr("limited", pick(in, {"true", "false"}));
      xml += "/></default>";
    }
    xml += "<worldbody>";
    do body(0, true);
    while (bodies < 8 && in.remaining_bytes() > 0 && in.ConsumeProbability<double>() < 0.3);
    xml += "</worldbody>";
    equalities();
    if (joints > 0 && in.ConsumeProbability<double>() < 0.1)
      xml += "<tendon><fixed name=\"t\"><joint joint=\"j0\" coef=\"1\"/></fixed></tendon>";
    if (joints > 0 && in.ConsumeProbability<double>() < 0.1) xml += "<actuator><motor joint=\"j0\"/></actuator>";
    xml += "</mujoco>";
    return xml;
  }
};

// ---------------------------------------------------------------------------
// The checks

void requireFiniteTransform(const Transform& X, const char* what) {
  fuzz::requireFinite(X.E, what, "readMjcfString");
  fuzz::requireFinite(X.r, what, "readMjcfString");
}

// Everything numeric the loader put in the model is a number (limits may be infinite, never NaN).
void checkLoaded(const MjcfModel& loaded) {
  const Model& model = loaded.model;
  fuzz::requireFinite(loaded.gravity, "gravity", "readMjcfString");
  for (int b = 0; b <= model.nv(); ++b) {
    const RigidInertia& I = model.inertia(b);
    fuzz::requireFinite(I.mass, "a body's mass", "readMjcfString");
    fuzz::requireFinite(I.h, "a body's first moment", "readMjcfString");
    fuzz::requireFinite(I.Ibar, "a body's rotational inertia", "readMjcfString");
  }
  for (const Frame& f : model.frames()) requireFiniteTransform(f.placement, "a frame's placement");
  for (const Joint& j : model.allJoints()) {
    requireFiniteTransform(j.placement, "a joint's placement");
    fuzz::requireFinite(j.axis, "a joint's axis", "readMjcfString");
    fuzz::requireFinite(j.rotor_inertia, "a joint's rotor inertia", "readMjcfString");
    fuzz::requireFinite(j.breakaway_friction, "a joint's friction", "readMjcfString");
    fuzz::requireFinite(j.viscous_friction, "a joint's viscous friction", "readMjcfString");
    if (std::isnan(j.lower) || std::isnan(j.upper)) fuzz::failure("a NaN limit", j.name.c_str());
    if (j.mimic.active()) {
      fuzz::requireFinite(j.mimic.multiplier, "a mimic multiplier", "readMjcfString");
      fuzz::requireFinite(j.mimic.offset, "a mimic offset", "readMjcfString");
    }
  }
}

void checkSolution(const Workspace& ws, const char* where) {
  fuzz::requireFinite(ws.solution.qdd, "qdd", where);
  fuzz::requireFinite(ws.solution.tau_control, "tau_control", where);
}

void checkStatus(const Status& status, const Workspace& ws, const char* where) {
  if (!fuzz::documented(status.code)) fuzz::failure("undocumented status", where);
  if (status.code == StatusCode::NonFinite) fuzz::failure("NonFinite for finite inputs", status.message);
  if (status.ok()) checkSolution(ws, where);
}

// The loaded model at (q, qd, tau): plain, forward and friction-aware dynamics.
void solveAt(const Model& model, const Task& task, Workspace& ws, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
             const Eigen::VectorXd& tau) {
  checkStatus(solveHybridDynamics(model, ws, q, qd, tau, task), ws, "solveHybridDynamics");
  checkStatus(forwardDynamics(model, ws, q, qd, tau, task), ws, "forwardDynamics");
  const Status status = solveWithFriction(model, ws, q, qd, tau, task);
  checkStatus(status, ws, "solveWithFriction");
  if (status.code == StatusCode::Infeasible) checkSolution(ws, "solveWithFriction (Infeasible)");
}

void solve(const MjcfModel& loaded, std::uint64_t seed) {
  const Model& model = loaded.model;
  if (model.dof() > 64) return;
  Task task(model);
  task.gravity = loaded.gravity;
  Workspace ws(model, task);
  Eigen::VectorXd q(model.nq()), qd = Eigen::VectorXd::Zero(model.nv()), tau = Eigen::VectorXd::Zero(model.nv());
  if (!neutralConfiguration(model, q).ok()) fuzz::failure("neutralConfiguration refused a loaded model", "");
  solveAt(model, task, ws, q, qd, tau);
  if (!randomConfiguration(model, seed, q).ok()) fuzz::failure("randomConfiguration refused a loaded model", "");
  for (Eigen::Index k = 0; k < qd.size(); ++k) {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    qd[k] = static_cast<double>(static_cast<std::int64_t>(seed >> 11) % 2001 - 1000) / 100.0;
    tau[k] = static_cast<double>(static_cast<std::int64_t>(seed >> 33) % 2001 - 1000);
  }
  model.followLeaders(q, qd);
  solveAt(model, task, ws, q, qd, tau);
}

// Loads `xml`; a loaded model is checked and solved. `strict`: also loaded in strict mode, which must refuse exactly
// the models with warnings. ZWANG_FUZZ_VERBOSE set: each document and its fate on stderr (what the generator reaches).
void loadAndCheck(const std::string& xml, std::uint64_t seed, bool strict) {
  static const bool verbose = std::getenv("ZWANG_FUZZ_VERBOSE") != nullptr;
  if (verbose) std::fprintf(stderr, "document: %s\n", xml.c_str());
  MjcfModel loaded;
  try {
    loaded = readMjcfString(xml);
  } catch (const ModelError& e) {
    if (verbose) std::fprintf(stderr, "refused: %s\n", e.what());
    if (e.what()[0] == '\0') fuzz::failure("ModelError without a message", "readMjcfString");
    return;
  }
  if (verbose)
    std::fprintf(stderr, "loaded: %d DOFs, %zu warnings\n", loaded.model.dof(), loaded.model.warnings().size());
  checkLoaded(loaded);
  bool strict_loaded = true;
  if (!strict) {
    solve(loaded, seed);
    return;
  }
  try {
    MjcfOptions strict;
    strict.strict = true;
    (void)readMjcfString(xml, strict);
  } catch (const ModelError&) {
    strict_loaded = false;
  }
  if (strict_loaded != loaded.model.warnings().empty())
    fuzz::failure("strict mode must refuse exactly the models with warnings", strict_loaded ? "loaded" : "refused");
  solve(loaded, seed);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 1 << 16) return -1;     // the loader is not meant for megabytes; keeps the fuzzer fast
  if (size > 0 && data[0] == '<') {  // the text as it is
    // Not the strict load: this mode's inputs are the large files (a load is most of an input's time).
    loadAndCheck(std::string(reinterpret_cast<const char*>(data), size), size, false);
    return 0;
  }
  FuzzedDataProvider in(data, size);
  const std::uint64_t seed = in.ConsumeIntegral<std::uint64_t>();
  Generator generator(in);
  loadAndCheck(generator.document(), seed, true);
  return 0;
}
