// `zwang info MODEL.urdf [--root L] [--tip L] [--base B] [--lock-mimic] [--json]`: what the
// loader made of a URDF tree or chain.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "cli.hpp"
#include "json_reader.hpp"
#include "solution_writer.hpp"
#include "zwang/zwang.hpp"

namespace zwang::cli {

namespace {

// Limits may be infinite ("none"): null in JSON, "-" in the table.
Json finiteOrNull(double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); }

std::string cell(double x) {
  if (!std::isfinite(x)) return "-";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", x);
  return buffer;
}

// Display width of UTF-8 text (link and joint names may hold any letters):
// the bytes that start a character.
std::size_t displayWidth(const std::string& text) {
  std::size_t n = 0;
  for (const char c : text) n += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
  return n;
}

// Left-aligned text columns, right-aligned numbers (cells starting with a digit, '-' or '.').
void printTable(const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> width;
  for (const auto& row : rows)
    for (std::size_t c = 0; c < row.size(); ++c) {
      if (width.size() <= c) width.push_back(0);
      width[c] = std::max(width[c], displayWidth(row[c]));
    }
  for (std::size_t r = 0; r < rows.size(); ++r) {
    std::string line = "";
    for (std::size_t c = 0; c < rows[r].size(); ++c) {
      const std::string& text = rows[r][c];
      const bool numeric =
          r > 0 && !text.empty() && (std::isdigit(static_cast<unsigned char>(text[0])) || text[0] == '-');
      const std::string pad(width[c] - displayWidth(text), ' ');
      line += "  " + (numeric ? pad + text : text + pad);
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    std::printf("%s\n", line.c_str());
  }
}

// The base (body 0: the root and every link welded to it): a fixed base never
// moves, so its mass does not enter the dynamics; a floating one's does.
// Either way it is shown apart from the bodies the joints move.
// The base link's body is Model::baseBody() (0 on a fixed base; a floating
// base's root joint moves it).
struct Masses {
  double moving = 0.0, base = 0.0;
  explicit Masses(const Model& model) : base(model.inertia(model.baseBody()).mass) {
    for (int b = model.baseBody() + 1; b < model.bodyCount(); ++b) moving += model.inertia(b).mass;
  }
};

std::string bodyLink(const Model& model, int body) { return model.frame(model.bodyFrame(body)).name; }

// The joint (index in joints()) that moves joint j's parent body; −1: it hangs from the base.
int parentJoint(const Model& model, int j) {
  const int body = model.parentBodyOfJoint(j);
  return body <= model.baseBody() ? -1 : model.dofs()[static_cast<std::size_t>(body - 1)].joint;
}

Json infoJson(const Model& model, const std::string& path) {
  // Every joint in the order of q and v: a floating base's root joint first (it hangs from the world, body 0).
  Json joints = Json::array();
  const int roots = static_cast<int>(model.allJoints().size() - model.joints().size());
  for (int a = 0; a < static_cast<int>(model.allJoints().size()); ++a) {
    const Joint& j = model.allJoints()[static_cast<std::size_t>(a)];
    const int k = a - roots;  // index in joints(), −1 for the root joint
    const int parent = k < 0 ? -1 : parentJoint(model, k);
    joints.push_back({{"name", j.name},
                      {"parent", parent < 0 ? Json(nullptr) : Json(model.joint(parent).name)},
                      {"parent_body", k < 0 ? 0 : model.parentBodyOfJoint(k)},
                      {"body", j.body()},
                      {"type", toString(j.type)},
                      {"nq", j.nq()},
                      {"nv", j.nv()},
                      {"q_index", j.q_index},
                      {"v_index", j.v_index},
                      {"axis", j.nv() == 1 ? Json({j.axis.x(), j.axis.y(), j.axis.z()}) : Json(nullptr)},
                      {"lower", finiteOrNull(j.lower)},
                      {"upper", finiteOrNull(j.upper)},
                      {"effort_limit", finiteOrNull(j.effort_limit)},
                      {"velocity_limit", finiteOrNull(j.velocity_limit)},
                      {"breakaway_friction", j.breakaway_friction},
                      {"kinetic_friction", j.kinetic_friction},
                      {"viscous_friction", j.viscous_friction},
                      {"rotor_inertia", j.rotor_inertia},
                      {"mimic", j.mimic.active() ? Json({{"leader", model.joint(j.mimic.leader).name},
                                                         {"multiplier", j.mimic.multiplier},
                                                         {"offset", j.mimic.offset}})
                                                 : Json(nullptr)}});
  }
  Json dofs = Json::array();
  for (const Dof& d : model.dofs()) dofs.push_back(d.name);
  Json frames = Json::array();
  for (const Frame& f : model.frames())
    frames.push_back({{"name", f.name}, {"body", f.body}, {"body_link", bodyLink(model, f.body)}});
  Json warnings = Json::array();
  for (const ModelWarning& w : model.warnings())
    warnings.push_back({{"code", toString(w.code)}, {"message", w.message}});
  const Masses mass(model);
  Json out = {{"file", path},       {"model", model.name()},
              {"dof", model.dof()}, {"base_type", toString(model.baseType())},
              {"nq", model.nq()},   {"nv", model.nv()}};
  if (model.baseType() == BaseType::Planar) {
    const Mat3 axes = model.basePlacement().rotationOfTarget();  // the plane's axes in the world
    const Vec3 origin = model.basePlacement().originOfTarget();
    const auto vec = [](const Vec3& v) { return Json::array({v.x(), v.y(), v.z()}); };
    out["base_plane"] = {{"origin", vec(origin)},
                         {"x_axis", vec(axes.col(0))},
                         {"y_axis", vec(axes.col(1))},
                         {"normal", vec(axes.col(2))}};
  }
  Json rest = {{"chain", model.isChain()},
               {"joints", std::move(joints)},
               {"dofs", std::move(dofs)},
               {"frames", std::move(frames)},
               {"moving_mass", mass.moving},
               {"base_mass", mass.base},
               {"total_mass", mass.moving + mass.base},
               {"warnings", std::move(warnings)}};
  for (auto& item : rest.items()) out[item.key()] = std::move(item.value());
  return out;
}

// "(0, 0, 1)" for the table (rounding's 1e-16s shown as 0; the JSON has the exact numbers).
std::string triple(const Vec3& v) {
  const auto shown = [](double x) { return std::abs(x) < 1e-12 ? 0.0 : x; };
  char text[96];
  std::snprintf(text, sizeof text, "(%g, %g, %g)", shown(v.x()), shown(v.y()), shown(v.z()));
  return text;
}

void printInfoTable(const Model& model, const std::string& path) {
  const int joints = static_cast<int>(model.joints().size());
  std::printf("%s: %d moving joint%s%s, %zu frames (%s)\n", model.name().c_str(), joints, joints == 1 ? "" : "s",
              model.isChain() ? "" : " in a tree", model.frames().size(), path.c_str());
  if (!model.hasFloatingBase()) {
    if (model.nq() == model.nv())
      std::printf("base: fixed (nq = nv = %d)\n", model.nv());
    else
      std::printf("base: fixed (nq = %d, nv = %d)\n", model.nq(), model.nv());
  } else {
    const int cq = model.baseConfigurationSize(), cv = model.baseVelocitySize();
    const int nq = model.nq() - cq, nv = model.nv() - cv;
    // One-DOF joints: one coordinate each; else the joints' coordinates, of so many joints.
    const std::string of =
        nq == joints ? std::to_string(joints) + (joints == 1 ? " joint" : " joints")
                     : std::to_string(nq) + " of " + std::to_string(joints) + (joints == 1 ? " joint" : " joints");
    std::printf("base: %s, link %s (q: %d base coordinates + %s = nq %d; v: %d + %d = nv %d)\n",
                toString(model.baseType()), model.frame(0).name.c_str(), cq, of.c_str(), model.nq(), cv, nv,
                model.nv());
    if (model.baseType() == BaseType::Planar)
      std::printf("  moving in the plane through %s with normal %s (x axis %s)\n",
                  triple(model.basePlacement().originOfTarget()).c_str(),
                  triple(model.basePlacement().rotationOfTarget().col(2)).c_str(),
                  triple(model.basePlacement().rotationOfTarget().col(0)).c_str());
  }
  std::printf("\njoints\n");
  std::vector<std::vector<std::string>> rows{{"#", "name", "parent", "type", "axis", "lower", "upper", "effort",
                                              "velocity", "breakaway", "kinetic", "viscous", "rotor_inertia"}};
  for (int k = 0; k < static_cast<int>(model.joints().size()); ++k) {
    const Joint& j = model.joint(k);
    char axis[64] = "-";  // a multi-DOF joint has none
    if (j.nv() == 1) std::snprintf(axis, sizeof axis, "(%g, %g, %g)", j.axis.x(), j.axis.y(), j.axis.z());
    const int parent = parentJoint(model, k);
    rows.push_back({std::to_string(k), j.name, parent < 0 ? "(base)" : model.joint(parent).name, toString(j.type), axis,
                    cell(j.lower), cell(j.upper), cell(j.effort_limit), cell(j.velocity_limit),
                    cell(j.breakaway_friction), cell(j.kinetic_friction), cell(j.viscous_friction),
                    cell(j.rotor_inertia)});
  }
  printTable(rows);
  if (!model.mimicJoints().empty()) {
    std::printf("\nmimic joints (their torque is carried by the leader's motor)\n");
    for (const int k : model.mimicJoints()) {
      const Joint& j = model.joint(k);
      const std::string& leader = model.joint(j.mimic.leader).name;
      std::printf("  %s follows %s: q = %s·q_%s + %s\n", j.name.c_str(), leader.c_str(),
                  cell(j.mimic.multiplier).c_str(), leader.c_str(), cell(j.mimic.offset).c_str());
    }
  }
  std::printf("\nframes\n");
  rows = {{"name", "body", "body link"}};
  for (const Frame& f : model.frames()) rows.push_back({f.name, std::to_string(f.body), bodyLink(model, f.body)});
  printTable(rows);
  const Masses mass(model);
  if (model.hasFloatingBase())
    std::printf(
        "\nmoving mass %s kg (bodies %d-%d), base mass %s kg (body %d: the root link and the links welded to "
        "it; it floats: in the dynamics)\n",
        cell(mass.moving).c_str(), model.baseBody() + 1, model.nv(), cell(mass.base).c_str(), model.baseBody());
  else
    std::printf("\nmoving mass %s kg (bodies 1-%d), base mass %s kg (welded to the fixed base, not in the dynamics)\n",
                cell(mass.moving).c_str(), model.nv(), cell(mass.base).c_str());
  const std::size_t warnings = model.warnings().size();
  if (warnings > 0) std::printf("%zu warning%s (on stderr)\n", warnings, warnings == 1 ? "" : "s");
  std::printf("units: rad, m, N·m or N (friction, effort), N·m·s/rad (viscous), kg·m² or kg (rotor inertia)\n");
}

}  // namespace

int commandInfo(int argc, char** argv) {
  const Arguments args =
      parseArguments("info", argc, argv, 2, {"--json", "--strict", "--attach-beyond-tip", "--lock-mimic"},
                     {"--root", "--tip", "--base"});
  if (args.help) {
    std::fputs(usageText("info"), stdout);
    return kExitOk;
  }
  if (args.positional.size() != 1)
    throw UsageError("info", args.positional.empty() ? "no URDF file given" : "more than one URDF file given");
  const std::string path = args.positional[0];
  Model model;
  try {
    model = problem::loadModelFile(path, commandLineUrdfOptions("info", args)).model;
  } catch (const ModelError& e) {
    throw CliError(kExitError, e.what());
  }
  printWarnings(model);
  if (args.has("--json"))
    writeOutput("", prettyDump(infoJson(model, path)) + "\n");
  else
    printInfoTable(model, path);
  return kExitOk;
}

}  // namespace zwang::cli
