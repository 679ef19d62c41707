// The second scenario of `zwang energy` (docs/evaluation.md, "The dual arm
// holding a box"): models/dual_panda.urdf (a torso turning about z, two Panda
// arms; 15 joints) holding a rigid box between its hands, standing still.
//
// The box: 3 kg, 0.3 m wide (y, between the hands) × 0.2 m deep × 0.2 m high,
// uniform, so its centre of mass is midway between the two tool0 origins,
// which grip the centres of its side faces. Its weight is carried by the
// hands; the split between them is statically indeterminate (any internal
// force can be added), and we take the symmetric one: (0, 0, −m g/2), world
// axes, at each tool0 origin. Their moments about the box's centre cancel
// (±0.15 m lever arms, equal forces), so it is the box's wrench exactly, and
// the least-norm split of it: the box itself feels no squeeze.
//
// The task holds everything still, 15 independent rows on 15 joints:
//   6 rows  left_tool0 relative to right_tool0 (reference axes): the closed loop;
//   6 rows  right_tool0 fixed in the world (world axes);
//   1 row   torso_link angular z (= q̈ of the torso);
//   2 rows  left_/right_panda_link1 angular z, own axes (= q̈₁ of each arm, the
//           elbow self-motion, as the Panda scenario locks it).
// Then q̈ = 0 and, as for the Panda,
//   plain (solveHybridDynamics): τ_control = G'(q) = RNEA(q, 0, 0) with the
//     box's wrenches;
//   friction-aware (solveWithFriction, all joints stuck): the least-effort
//     maximiser, |τ_control,j| = max(0, |G'_j| − margin·f_j).
// Checked in every solve: rank 15 (an error otherwise: q̈ would not be
// determined). That the solver's answer is right (q̈ = 0, the closed form,
// the closure τ_control − μ = G', τ_c = Σ Jᵀ A ν from the frames' Jacobians,
// the loop's force putting no torque on the torso) is the tests' to show
// (test_cli_energy), not the tool's.
// The postures are data: models/dual_panda_postures.json, solved once by damped
// least squares (test/cli/dual_panda_postures.cpp, ctest dual_panda_postures);
// every one read is checked (hands on the box, joint-limit distance) before
// anything is solved, so a bad file is refused, naming the file and the field.
#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "cli.hpp"
#include "dual_arm_box.hpp"
#include "energy_report.hpp"
#include "json_reader.hpp"
#include "zwang/zwang.hpp"

namespace zwang::cli {

namespace {

constexpr int kDof = 15;
constexpr double kBoxMass = 3.0;             // [kg]
constexpr double kLimitDistance = 0.2;       // every joint at least this far inside its limits [rad]
constexpr double kPostureTolerance = 1e-10;  // hand position [m] and orientation [rad] of a stored posture
constexpr const char* kPosturesFile = "dual_panda_postures.json";

// One posture of the postures file: where the box is and the joints' q.
struct Posture {
  std::string name, what;
  dual_arm::BoxPlacement box;  // torso angle [rad], the box's centre in the torso frame [m]
  Eigen::VectorXd q;           // torso, left arm 1-7, right arm 1-7 [rad]
};

// What the dual arm's report adds to a posture's solves: the input check's result
// and the loop's force.
struct PostureDetail {
  double hand_error = 0, limit_distance = 0;
  // ν of the relative rows per variant: the wrench on the left hand, right_tool0's axes
  std::array<Vec6, energy::kVariantCount> loop;
};

using energy::small;

// A posture's fields from the postures file, then the input check: the hands
// on the box, every joint inside its limits (CliError naming file and field).
Posture readPosture(const Model& model, const JsonReader& in, const Json& value, const std::string& path,
                    PostureDetail& d) {
  const Json& object = in.object(value, path, {"name", "what", "torso", "box", "q"});
  for (const char* key : {"name", "what", "torso", "box", "q"})
    if (!object.contains(key)) in.fail(childPath(path, key), "missing");
  Posture p;
  p.name = in.string(object["name"], childPath(path, "name"));
  p.what = in.string(object["what"], childPath(path, "what"));
  p.box.torso = in.number(object["torso"], childPath(path, "torso"));
  p.box.centre = in.numbers(object["box"], childPath(path, "box"), 3, "x, y, z");
  p.q = in.numbers(object["q"], childPath(path, "q"), kDof, "one per joint");
  Workspace ws(model);
  if (const Status s = dual_arm::boxError(model, ws, p.q, p.box, d.hand_error); !s)
    in.fail(childPath(path, "q"), s.message);
  d.limit_distance = std::numeric_limits<double>::infinity();
  for (int j = 0; j < kDof; ++j)
    d.limit_distance = std::min({d.limit_distance, p.q[j] - model.joint(j).lower, model.joint(j).upper - p.q[j]});
  if (!(d.hand_error < kPostureTolerance))
    in.fail(childPath(path, "q"),
            "the hands are " + fmt(d.hand_error) + " from the box (at most " + fmt(kPostureTolerance) + " m or rad)");
  if (!(d.limit_distance > kLimitDistance))
    in.fail(childPath(path, "q"),
            "a joint is " + fmt(d.limit_distance) + " rad from its limit (at least " + fmt(kLimitDistance) + ")");
  return p;
}

// The postures of models/dual_panda_postures.json (next to the URDF), each checked.
std::vector<Posture> readPostures(const ReportCommand& report, const Model& model,
                                  std::vector<PostureDetail>& details) {
  const std::string file =
      (std::filesystem::path(modelsDirectory(report.args, kPosturesFile)) / kPosturesFile).string();
  const JsonReader in(file);
  std::string text;
  try {
    text = readFile(file, kMaxInputBytes);
  } catch (const CliError& e) {
    throw CliError(kExitError, report.name + ": " + e.what() + " (use --models DIR)");
  }
  const Json root = parseJson(text, file);
  const Json& object = in.object(root, "", {"about", "model", "postures"});
  for (const char* key : {"model", "postures"})
    if (!object.contains(key)) in.fail(key, "missing");
  if (in.string(object["model"], "model") != "dual_panda.urdf") in.fail("model", "not dual_panda.urdf");
  const Json& postures = in.array(object["postures"], "postures");
  if (postures.empty()) in.fail("postures", "no postures");
  std::vector<Posture> result;
  for (std::size_t k = 0; k < postures.size(); ++k) {
    details.emplace_back();
    result.push_back(readPosture(model, in, postures[k], childPath("postures", k), details.back()));
  }
  return result;
}

// readPostures with its errors as the report's ("energy: FILE: FIELD: what").
std::vector<Posture> checkedPostures(const ReportCommand& report, const Model& model,
                                     std::vector<PostureDetail>& details) {
  try {
    return readPostures(report, model, details);
  } catch (const CliError& e) {
    const std::string message = e.what();
    if (message.rfind(report.name + ": ", 0) == 0) throw;
    throw CliError(e.exitCode(), report.name + ": " + message);
  }
}

// The hold-still task with the box's weight on the hands; `loop_row` is set to the loop's first row.
Task holdBoxTask(const Model& model, int& loop_row) {
  Task task(model);  // gravity (0, 0, −9.81)
  loop_row =
      task.addRelativeConstraint("left_tool0", "right_tool0", ConstraintMatrix::Identity(6, 6), Expressed::Reference);
  task.addConstraint("right_tool0", ConstraintMatrix::Identity(6, 6), Expressed::World);
  ConstraintMatrix lock = ConstraintMatrix::Zero(6, 1);
  lock(5, 0) = 1.0;  // angular z, the body's own axes
  for (const char* body : {"torso_link", "left_panda_link1", "right_panda_link1"})
    task.addConstraint(body, lock, Expressed::Local);
  const Vec6 half_weight = (Vec6() << 0.0, 0.0, -0.5 * kBoxMass * 9.81, 0.0, 0.0, 0.0).finished();
  task.wrench(task.addWrench("left_tool0", Expressed::World)) = half_weight;
  task.wrench(task.addWrench("right_tool0", Expressed::World)) = half_weight;
  return task;
}

energy::PostureResult run(const Model& model, const Posture& posture, PostureDetail& d) {
  energy::PostureResult r;
  r.name = posture.name;
  r.q = posture.q;
  const std::string where = std::string("energy: dual arm, posture ") + posture.name + ": ";
  int loop_row = 0;
  const Task task = holdBoxTask(model, loop_row);
  Workspace ws(model, task);
  for (int v = 0; v < energy::kVariantCount; ++v) {
    const energy::Variant& variant = energy::kVariants[v];
    if (const Status status = energy::solveAtRest(model, task, r.q, ws, variant); !status)
      throw CliError(kExitError, where + variant.name + ": " + status.message);
    if (ws.solution.balance.rank != kDof || ws.solution.balance.singular)
      throw CliError(kExitError, where + variant.name + ": the hold-still task has rank " +
                                     std::to_string(ws.solution.balance.rank) + ", not " + std::to_string(kDof) +
                                     " (q̈ is not fully determined)");
    const auto k = static_cast<std::size_t>(v);
    r.variant[k] = energy::variantResult(variant, ws.solution.tau_control, ws);
    d.loop[k] = ws.solution.nu.segment<6>(loop_row);
  }
  r.ok = true;  // rank 15 in every solve (an error above otherwise)
  return r;
}

// The joints' short names in the charts: t (torso), L1–L7, R1–R7.
std::string jointLabel(int j) { return j == 0 ? "t" : (j <= 7 ? "L" : "R") + std::to_string(j <= 7 ? j : j - 7); }

// The dual Panda of models/ (CliError when it does not load or is another model).
Model loadDualPanda(const ReportCommand& report, std::filesystem::path& urdf) {
  Model model = energy::loadScenarioModel(report, "dual_panda.urdf", UrdfOptions(), urdf);
  bool as_expected = model.dof() == kDof;
  for (const char* frame : {"torso_link", "left_panda_link1", "right_panda_link1", "left_tool0", "right_tool0"})
    as_expected = as_expected && model.hasFrame(frame);
  if (as_expected)
    as_expected = model.jointIndex("torso_joint") == 0 && model.jointIndex("left_panda_joint1") == 1 &&
                  model.jointIndex("right_panda_joint1") == 8;
  if (!as_expected)
    throw CliError(kExitError, report.name + ": " + urdf.string() +
                                   ": expected the 15-joint dual Panda (torso_joint, left_panda_joint1-7, "
                                   "right_panda_joint1-7) with frames left_tool0 and right_tool0");
  return model;
}

// The dual arm holding the box still in each posture of the postures file.
class DualArmScenario final : public Scenario {
 public:
  explicit DualArmScenario(const ReportCommand& report)
      : model_(loadDualPanda(report, urdf_)), placements_(checkedPostures(report, model_, details_)) {
    for (std::size_t p = 0; p < placements_.size(); ++p) postures_.push_back(run(model_, placements_[p], details_[p]));
  }
  ScenarioFiles files() const override {
    return {{"dual_energy.csv"},
            "pose, variant, q1-15, tau1-15 = tau_control, mu1-15, tau_norm, tau_sq, tau_abs_sum,\nloop_fx..loop_nz",
            "dual_energy.gp",
            "dual_energy.png, dual_energy_joints.png"};
  }
  bool ok() const override {
    return std::all_of(postures_.begin(), postures_.end(), [](const energy::PostureResult& r) { return r.ok; });
  }
  void print() const override;
  std::string csvText(std::size_t) const override {
    return energy::armCsv(postures_, ",loop_fx,loop_fy,loop_fz,loop_nx,loop_ny,loop_nz", [this](std::size_t p, int v) {
      return Eigen::VectorXd(details_[p].loop[static_cast<std::size_t>(v)]);
    });
  }
  std::string plotScript() const override;

 private:
  void printSetting() const;
  void printPostures() const;
  void printTorques() const;
  void printLoopForces() const;
  void printChecks() const;

  std::filesystem::path urdf_;
  Model model_;
  std::vector<PostureDetail> details_;  // before placements_: readPostures fills it
  std::vector<Posture> placements_;
  std::vector<energy::PostureResult> postures_;
};

// The same two charts as the Panda's (energy.gp), in the same style.
std::string DualArmScenario::plotScript() const {
  const energy::ArmCharts charts{"posture",
                                 "dual_energy.png",
                                 "Dual arm holding a 3 kg box still: motor effort ‖τ_{control}‖",
                                 "1400,800",
                                 "dual_energy_joints.png",
                                 "Dual arm holding a box: |τ_{control,j}| per joint (bars; t = torso, L/R = "
                                 "left/right arm) and breakaway friction f_j (red)"};
  return energy::armPlotScript(files().script, charts, postures_, model_, jointLabel);
}

// What the report shows: the model, the box, the task and the postures' source.
void DualArmScenario::printSetting() const {
  std::printf("\nzwang energy: %s (torso + two Pandas, 15 joints) holding a box still, at rest\n",
              energy::shownPath(urdf_).c_str());
  std::printf(
      "box: %g kg, 0.3 m wide (y, between the hands) x 0.2 m deep x 0.2 m high, centre midway between the hands;\n"
      "its weight split evenly: (0, 0, -%g) N at each tool0 origin, world axes (no moment: the lever arms cancel)\n",
      kBoxMass, 0.5 * kBoxMass * 9.81);
  std::printf(
      "task: left_tool0 relative to right_tool0 (6 rows, right_tool0's axes: the closed loop) + right_tool0 fixed\n"
      "(6 rows, world axes) + torso_link, left_panda_link1, right_panda_link1 angular z (= qdd of torso, L1, R1)\n"
      "fixed: 15 independent rows on 15 joints, qdd = 0 exactly\n");
  std::printf("breakaway friction f [N·m]: torso %s, each arm", fmt(model_.joint(0).breakaway_friction).c_str());
  for (int j = 1; j <= 7; ++j) std::printf(" %s", fmt(model_.joint(j).breakaway_friction).c_str());
  std::printf(
      "\npostures: the hands at the box's side faces (box centre +-0.15 m along the torso's y), tool0 z towards\n"
      "the box, x down; solved by damped least squares from make_dual_panda.py --check's grasp\n\n");
}

// The postures (torso, box, hand error, closest limit) and their q.
void DualArmScenario::printPostures() const {
  std::printf(
      "postures: torso angle [rad], box centre in the torso frame [m], hand error [m or rad], closest limit [rad]\n");
  std::vector<std::vector<std::string>> postures{
      {"posture", "what", "torso", "box x", "y", "z", "hand error", "closest limit"}};
  for (std::size_t p = 0; p < postures_.size(); ++p) {
    const Posture& posture = placements_[p];
    postures.push_back({posture.name, posture.what, fmt(posture.box.torso), fmt(posture.box.centre.x()),
                        fmt(posture.box.centre.y()), fmt(posture.box.centre.z()), small(details_[p].hand_error),
                        fmt(details_[p].limit_distance, "%.3f")});
  }
  printColumns(postures, 2);

  std::printf("\nq [rad]: torso, left arm 1-7, right arm 1-7\n");
  std::vector<std::vector<std::string>> qs{
      {"posture", "t", "L1", "L2", "L3", "L4", "L5", "L6", "L7", "R1", "R2", "R3", "R4", "R5", "R6", "R7"}};
  for (const energy::PostureResult& r : postures_) {
    std::vector<std::string> row{r.name};
    for (const double q : r.q) row.push_back(fmt(q, "%.4f"));
    qs.push_back(row);
  }
  printColumns(qs);
}

// tau_control per joint and variant.
void DualArmScenario::printTorques() const {
  std::printf("\ntau_control per joint [N·m]\n");
  std::vector<std::vector<std::string>> joints{{"posture", "variant"}};
  for (int j = 0; j < kDof; ++j) joints[0].push_back(jointLabel(j));
  for (const energy::PostureResult& r : postures_)
    for (int v = 0; v < energy::kVariantCount; ++v) {
      std::vector<std::string> row{v == 0 ? r.name : "", energy::kVariants[v].name};
      for (const double tau : r.variant[static_cast<std::size_t>(v)].tau) row.push_back(fmt(tau, "%.3g"));
      joints.push_back(row);
    }
  printColumns(joints, 2);
}

// The closed loop's internal force per posture.
void DualArmScenario::printLoopForces() const {
  std::printf(
      "\nthe loop's force: nu of the relative rows, the wrench on the left hand (its opposite on the right arm) in\n"
      "right_tool0's axes (z points from the right hand to the left: fz > 0 pulls the hands apart, fz < 0 squeezes;\n"
      "x down); N and N·m; plain solver. It is the task rows' share of the motor torques, internal to the loop (it\n"
      "puts no torque on the torso); the box's own load is in the wrenches, split evenly, so the box feels no "
      "squeeze.\n");
  std::vector<std::vector<std::string>> loop{{"posture", "fx", "fy", "fz", "nx", "ny", "nz"}};
  for (std::size_t p = 0; p < postures_.size(); ++p) {
    std::vector<std::string> row{postures_[p].name};
    for (int k = 0; k < 6; ++k) row.push_back(fmt(details_[p].loop[0][k]));
    loop.push_back(row);
  }
  printColumns(loop);
}

// What the report checks itself (the solver's answer is the tests' to check).
void DualArmScenario::printChecks() const { std::printf("check: rank 15 in every solve\n"); }

void DualArmScenario::print() const {
  printSetting();
  printPostures();
  printTorques();
  printLoopForces();
  energy::printEffortTable("posture", postures_);
  printChecks();
}

}  // namespace

std::unique_ptr<Scenario> energy::dualArmScenario(const ReportCommand& report) {
  return std::make_unique<DualArmScenario>(report);
}

}  // namespace zwang::cli
