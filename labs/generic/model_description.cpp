// Reading a description (model_description.h) into a LoadedModel, field by field, each checked
// (model_description_json.h); and where a model file's description is found when MuJoCo's parser is not
// there (the WebAssembly grader and page).
#include "labs/generic/model_description.h"

#include <cctype>
#include <filesystem>

#include "labs/generic/model_description_json.h"
#include "labs/lab.h"
#include "physics/constrained_mechanism.h"
#include "physics/model_file/closure_rows.h"
#include "physics/model_file/number_text.h"

namespace dyn::app {
namespace {

using namespace description;
using model_file::LoadedModel;
using model_file::ModelFileError;
using Vec3 = Eigen::Vector3d;

std::string g_descriptions;  // setDescriptionsFolder's folder ("": model files are parsed)

// Per coordinate (rate): its name, body, type, q index and range.
void readJoints(const JsonView& j, LoadedModel& m) {
  const int dof = m.mechanism.tree.dof(), nq = int(m.q0.size());
  j.size(std::size_t(dof), std::size_t(dof));
  for (int i = 0; i < dof; ++i) {
    const JsonView x = j.at(std::size_t(i));
    x.onlyKeys({"name", "body", "type", "qpos", "limited", "lower", "upper"});
    model_file::Joint jt;
    jt.name = name(x["name"]), jt.body = name(x["body"]), jt.type = x["type"].oneOf({"hinge", "slide", "ball", "free"});
    jt.qpos = index(x["qpos"], 0, nq - 1), jt.limited = x["limited"].boolean(), jt.lower = num(x["lower"]), jt.upper = num(x["upper"]);
    if (jt.limited && !(jt.lower <= jt.upper)) x["upper"].fail("expected an upper limit ≥ the lower one");
    // Its coordinate and kind are the tree body's (a ball's rates read the quaternion from q[qpos]).
    const auto& body = m.mechanism.tree.bodies[std::size_t(i)];
    if (jt.qpos != body.q_index) x["qpos"].fail("expected " + std::to_string(body.q_index) + ", the tree body's coordinate in q");
    const JointType t = body.joint;
    const bool fits = jt.type == "hinge" ? t == JointType::Revolute : jt.type == "slide" ? t == JointType::Prismatic
                    : jt.type == "ball"  ? t == JointType::Ball      : t != JointType::Revolute;
    if (!fits) x["type"].fail("expected the type of tree body " + std::to_string(i) + "'s joint");
    m.joints.push_back(jt);
  }
}

// The closures (one per kept point_closure constraint, first), every row of every closure, and the
// constraints after them (contacts: one each).
void readLoops(const JsonView& root, LoadedModel& m) {
  const int dof = m.mechanism.tree.dof(), nq = int(m.q0.size());
  const auto& constraints = m.mechanism.constraints;
  const JsonView cl = root["closures"];
  for (std::size_t i = 0, n = cl.size(0, constraints.size()); i < n; ++i) {
    const JsonView x = cl.at(i);
    x.onlyKeys({"name", "kind", "body1", "body2", "kept", "dropped", "link1", "link2", "point1", "point2"});
    if (std::string(constraints[i]->kind()) != "point_closure")
      x.fail("expected a closure for each point_closure of /mechanism/constraints, first (constraint " + std::to_string(i) + " is a " + constraints[i]->kind() + ")");
    model_file::Closure c;
    c.name = name(x["name"]), c.kind = x["kind"].oneOf({"connect", "weld"}), c.body1 = name(x["body1"]), c.body2 = name(x["body2"]);
    c.kept = names(x["kept"], 6), c.dropped = names(x["dropped"], 6);
    for (const JsonView& rows : {x["kept"], x["dropped"]})
      for (std::size_t k = 0; k < rows.size(); ++k)
        if (model_file::rowIndex(rows.at(k).string()) < 0) rows.at(k).fail("expected a row name: wx wy wz x y z");
    c.link1 = index(x["link1"], -1, dof - 1), c.link2 = index(x["link2"], -1, dof - 1);
    c.point1 = matrix<Vec3>(x["point1"]), c.point2 = matrix<Vec3>(x["point2"]);
    m.closures.push_back(c);
  }
  const JsonView every = root["every_closure_row"];
  for (std::size_t i = 0, n = every.size(0, 4 * kMaxDof); i < n; ++i) {
    const JsonView x = every.at(i);
    x.onlyKeys({"name", "rows", "dropped"});
    model_file::EveryRow e{name(x["name"]), readConstraint(x["rows"], m.mechanism.tree, nq), names(x["dropped"], 6)};
    if (std::string(e.rows->kind()) != "point_closure") x["rows"]["kind"].fail("expected \"point_closure\" (every row of a closure)");
    m.every_closure_row.push_back(e);
  }
  const JsonView co = root["contacts"];
  const std::size_t after = constraints.size() - m.closures.size();
  co.size(after, after);
  for (std::size_t i = 0; i < after; ++i) {
    const JsonView x = co.at(i);
    x.onlyKeys({"name", "kind", "body", "link", "mu"});
    model_file::Contact c{name(x["name"]), x["kind"].oneOf({"rolling", "plane_contact", "joint_limit", "joint_coupling", "tendon_coupling"}),
                          name(x["body"]), index(x["link"], 0, dof - 1), num(x["mu"], 0, 10)};
    const ConstraintPtr<Spatial>& k = constraints[m.closures.size() + i];
    if (c.kind != k->kind()) x["kind"].fail("expected \"" + std::string(k->kind()) + "\", constraint " + std::to_string(m.closures.size() + i) + "'s kind");
    if (c.link != k->attachment().b.index) x["link"].fail("expected " + std::to_string(k->attachment().b.index) + ", the body constraint " +
                                                           std::to_string(m.closures.size() + i) + " acts on");
    if (c.kind == "joint_limit" && !m.joints[std::size_t(c.link)].limited) x["link"].fail("expected the limited joint the stop is on");
    m.contacts.push_back(c);
  }
}

std::vector<model_file::TendonTerm> readPath(const JsonView& j, int dof, int nq) {
  std::vector<model_file::TendonTerm> path;
  for (std::size_t i = 0, n = j.size(1, kMaxDof); i < n; ++i) {
    const JsonView t = j.at(i);
    t.onlyKeys({"coordinate", "coef", "qpos"});
    path.push_back({index(t["coordinate"], 0, dof - 1), num(t["coef"]), index(t["qpos"], -1, nq - 1)});
  }
  return path;
}

void readDrives(const JsonView& root, LoadedModel& m) {
  const int dof = m.mechanism.tree.dof(), nq = int(m.q0.size());
  const JsonView a = root["actuators"];
  for (std::size_t i = 0, n = a.size(0, kMaxDof); i < n; ++i) {
    const JsonView x = a.at(i);
    x.onlyKeys({"name", "joint", "tendon", "path", "gear", "gain", "bias", "ctrl_limited", "force_limited", "ctrl_range", "force_range"});
    model_file::Actuator u;
    u.name = name(x["name"]), u.joint = name(x["joint"]), u.tendon = name(x["tendon"]), u.path = readPath(x["path"], dof, nq);
    u.gear = num(x["gear"]), u.gain = num(x["gain"]);
    const Vec3 bias = matrix<Vec3>(x["bias"]);
    u.bias = {bias[0], bias[1], bias[2]};
    u.ctrl_limited = x["ctrl_limited"].boolean(), u.force_limited = x["force_limited"].boolean();
    const Eigen::Vector2d c = matrix<Eigen::Vector2d>(x["ctrl_range"]), f = matrix<Eigen::Vector2d>(x["force_range"]);
    u.ctrl_lower = c[0], u.ctrl_upper = c[1], u.force_lower = f[0], u.force_upper = f[1];
    m.actuators.push_back(u);
  }
  const JsonView t = root["tendons"];
  for (std::size_t i = 0, n = t.size(0, kMaxDof); i < n; ++i) {
    const JsonView x = t.at(i);
    x.onlyKeys({"name", "path", "stiffness", "rest", "damping", "frictionloss", "friction_width"});
    m.tendons.push_back({name(x["name"]), readPath(x["path"], dof, nq), num(x["stiffness"]), num(x["rest"]), num(x["damping"], 0, kLargest),
                         num(x["frictionloss"], 0, kLargest), num(x["friction_width"], 1e-12, kLargest)});
  }
}

model_file::Geom::Shape shapeOf(const JsonView& j) {
  using S = model_file::Geom::Shape;
  const std::string s = j.oneOf({"sphere", "capsule", "cylinder", "box", "plane", "mesh"});
  return s == "sphere" ? S::Sphere : s == "capsule" ? S::Capsule : s == "cylinder" ? S::Cylinder : s == "box" ? S::Box : s == "plane" ? S::Plane : S::Mesh;
}

std::shared_ptr<const TriangleMesh> readMesh(const JsonView& j) {
  j.onlyKeys({"vertices", "triangles"});
  auto mesh = std::make_shared<TriangleMesh>();
  const JsonView v = j["vertices"], t = j["triangles"];
  for (std::size_t i = 0, n = v.size(1, 1u << 22); i < n; ++i) {
    const Eigen::Vector3f p = matrix<Vec3>(v.at(i)).cast<float>();
    mesh->vertices.push_back(p);
    mesh->box.extend(p.cast<double>());
  }
  for (std::size_t i = 0, n = t.size(1, 1u << 23); i < n; ++i) {
    const JsonView f = t.at(i);
    f.size(3, 3);
    const int last = int(mesh->vertices.size()) - 1;
    mesh->triangles.push_back({std::uint32_t(index(f.at(0), 0, last)), std::uint32_t(index(f.at(1), 0, last)), std::uint32_t(index(f.at(2), 0, last))});
  }
  return mesh;
}

void readDrawing(const JsonView& d, LoadedModel& m) {
  d.onlyKeys({"geoms", "meshes", "bones", "notes"});
  const int dof = m.mechanism.tree.dof();
  std::vector<std::shared_ptr<const TriangleMesh>> meshes;
  for (std::size_t i = 0, n = d["meshes"].size(0, std::size_t(model_file::kMaxGeoms)); i < n; ++i) meshes.push_back(readMesh(d["meshes"].at(i)));
  for (std::size_t i = 0, n = d["geoms"].size(0, std::size_t(model_file::kMaxGeoms)); i < n; ++i) {
    const JsonView x = d["geoms"].at(i);
    x.onlyKeys({"shape", "name", "body", "link", "pos", "rot", "size", "mesh", "rgba", "file_color"});
    model_file::Geom g;
    g.shape = shapeOf(x["shape"]), g.name = name(x["name"]), g.body = name(x["body"]), g.link = index(x["link"], -1, dof - 1);
    g.pos = matrix<Vec3>(x["pos"]), g.rot = matrix<Eigen::Matrix3d>(x["rot"]), g.size = matrix<Vec3>(x["size"]);
    if (!(g.size.minCoeff() >= 0)) x["size"].fail("expected sizes ≥ 0 (m)");
    const bool mesh = g.shape == model_file::Geom::Shape::Mesh;
    if (mesh != !x["mesh"].raw().is_null()) x["mesh"].fail(mesh ? "expected the index of its mesh in /drawing/meshes" : "expected null (not a mesh)");
    if (mesh) g.mesh = meshes[std::size_t(index(x["mesh"], 0, int(meshes.size()) - 1))];
    const JsonView rgba = x["rgba"];
    for (std::size_t k = 0, n = rgba.size(4, 4); k < n; ++k) g.rgba[k] = float(num(rgba.at(k), 0, 1));
    g.file_color = x["file_color"].boolean();
    m.drawing.geoms.push_back(g);
  }
  for (std::size_t i = 0, n = d["bones"].size(0, kMaxItems); i < n; ++i) {
    const JsonView x = d["bones"].at(i);
    x.onlyKeys({"link", "from", "to"});
    m.drawing.bones.push_back({index(x["link"], 0, dof - 1), matrix<Vec3>(x["from"]), matrix<Vec3>(x["to"])});
  }
  m.drawing.notes = names(d["notes"]);
}

// Where runs start (the keyframe it was exported with, or q0 at rest) and its controls.
void readStart(const JsonView& s, LoadedModel& m) {
  s.onlyKeys({"key", "q", "v", "ctrl"});
  const std::size_t nq = std::size_t(m.q0.size()), dof = std::size_t(m.mechanism.tree.dof()), nu = m.actuators.size();
  m.key = name(s["key"]);
  m.start_q = vector(s["q"], nq, nq), m.start_v = vector(s["v"], dof, dof), m.ctrl = vector(s["ctrl"], nu, nu);
}

// The options a model file's load takes, as they apply to a description.
void applyOptions(const std::string& file, const model_file::LoadOptions& options, LoadedModel& m) {
  if (!options.closures.empty() || !options.rolling.empty() || !options.contacts.empty())
    throw ModelFileError(file + ": closures, wheels or contacts given beside a description; it holds its own (export the model file with them)");
  if (!options.key.empty() && options.key != m.key)
    throw ModelFileError(file + ": --key '" + options.key + "': a description starts where it was exported (" +
                         (m.key.empty() ? std::string("q0 at rest") : "keyframe '" + m.key + "'") +
                         "); export the model file with --key " + options.key);
  if (options.joint_limits) return;
  // A data lab's load: the limits read and noted, not held (as model_file::load with joint_limits false).
  std::vector<ConstraintPtr<Spatial>> kept(m.mechanism.constraints.begin(), m.mechanism.constraints.begin() + std::ptrdiff_t(m.closures.size()));
  std::vector<model_file::Contact> contacts;
  for (std::size_t i = 0; i < m.contacts.size(); ++i) {
    if (m.contacts[i].kind == "joint_limit") continue;
    kept.push_back(m.mechanism.constraints[m.closures.size() + i]);
    contacts.push_back(m.contacts[i]);
  }
  for (const model_file::Joint& j : m.joints)
    if (j.limited)
      m.notes.push_back("joint '" + j.name + "': limit [" + model_file::detail::numberText(j.lower) + ", " + model_file::detail::numberText(j.upper) + "] " + (j.type == "hinge" ? "rad" : "m") +
                        " read, not enforced (a data lab: its controller keeps the joint inside)");
  m.mechanism.constraints = kept;
  m.contacts = contacts;
}

LoadedModel readRoot(const JsonView& r, const std::string& file) {
  r.requireObject();
  if (!r.has("format") || !r["format"].raw().is_string() || r["format"].string() != kDescriptionFormat)
    r["format"].fail(std::string("expected \"") + kDescriptionFormat + "\" (a file `dynlab model FILE --export DESC.json` writes)");
  if (r["version"].integer(0, 1LL << 40) != kDescriptionVersion)
    r["version"].fail("expected format version " + std::to_string(kDescriptionVersion) + ", the one this dynlab reads; export the model file again with this dynlab");
  r.onlyKeys({"format", "version", "source", "timestep", "dof", "q0", "coordinates", "joints", "bodies", "mechanism", "closures",
              "every_closure_row", "contacts", "actuators", "tendons", "keyframes", "start", "notes", "drawing"});
  LoadedModel m;
  m.file = file;
  name(r["source"]);
  m.timestep = num(r["timestep"], 0, 1e3);
  m.q0 = vector(r["q0"], 1, kMaxDof);
  m.mechanism = readMechanism(r["mechanism"], int(m.q0.size()));
  m.coordinates = names(r["coordinates"], kMaxDof);
  if (m.coordinates.size() != std::size_t(m.q0.size())) r["coordinates"].fail("expected one name per entry of /q0 (" + std::to_string(m.q0.size()) + ")");
  readJoints(r["joints"], m);
  m.bodies = names(r["bodies"], kMaxDof);
  readLoops(r, m);
  readDrives(r, m);
  m.keyframes = names(r["keyframes"]);
  readStart(r["start"], m);
  m.notes = names(r["notes"]);
  readDrawing(r["drawing"], m);
  m.dof = index(r["dof"], 0, m.mechanism.tree.dof());
  return m;
}

// The start must hold the loops, as a model file's keyframe must (controls.cpp): every row of every
// closure, the dropped ones too, and their velocity form with the start's rates. An export always
// does; an edited description that does not is refused here rather than stopping its first run.
void checkStart(const std::string& file, const LoadedModel& m, ConstrainedMechanism<Spatial>& mech) {
  if (m.closures.empty()) return;
  if (const std::string why = model_file::EveryClosureRow(m).opened(m.start_q); !why.empty())
    throw ModelFileError(file + ": /start/q: expected a pose that holds the model's loops (" + why + "); export the model file again");
  if (m.contacts.empty())
    if (const double gap = mech.residual(m.start_q, m.start_v); !(gap <= 1e-9))
      throw ModelFileError(file + ": /start/v: expected rates that keep the loops closed (|G v| " + model_file::detail::numberText(gap) +
                           "); export the model file again");
}

}  // namespace

bool isDescription(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".json";
}

LoadedModel readDescriptionText(const std::string& text, const std::string& file, const model_file::LoadOptions& options) {
  try {
    const json doc = parseJsonText(text, file);
    LoadedModel m = readRoot(JsonView(doc, file), file);
    applyOptions(file, options, m);
    // The engines' own checks (sizes, bodies named) before anything runs.
    ConstrainedMechanism<Spatial> check(m.mechanism);
    checkStart(file, m, check);
    return m;
  } catch (const InputError& e) {
    throw ModelFileError(e.what());
  } catch (const std::invalid_argument& e) {
    throw ModelFileError(file + ": /mechanism: a mechanism dynlab can run (" + e.what() + ")");
  } catch (const std::length_error& e) {
    throw ModelFileError(file + ": /mechanism: a mechanism within dynlab's sizes (" + e.what() + ")");
  }
}

LoadedModel readDescription(const std::string& path, const model_file::LoadOptions& options) {
  std::string text;
  try {
    text = readTextFile(path, kMaxDescriptionBytes);
  } catch (const InputError& e) {
    throw ModelFileError(e.what());
  }
  return readDescriptionText(text, path, options);
}

void setDescriptionsFolder(const std::string& folder) { g_descriptions = folder; }

std::string descriptionFor(const std::string& folder, const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path tree = fs::weakly_canonical(fs::path(labsRoot()).parent_path(), ec), file = fs::weakly_canonical(path, ec);
  const fs::path rel = file.lexically_relative(tree);
  if (ec || rel.empty() || *rel.begin() == "..") return "";
  return (fs::path(folder) / rel).string() + ".json";
}

LoadedModel loadModelOrDescription(const std::string& path, const model_file::LoadOptions& options) {
  if (isDescription(path)) return readDescription(path, options);
  if (g_descriptions.empty()) return model_file::load(path, options);
  const std::string desc = descriptionFor(g_descriptions, path);
  std::error_code ec;
  if (desc.empty() || !std::filesystem::is_regular_file(desc, ec))
    throw ModelFileError(path + ": not a dynlab model description, and this build reads no MJCF/URDF file (no MuJoCo parser); export it with a "
                                "native dynlab: `dynlab model " + path + " --export " + std::filesystem::path(path).filename().string() +
                         ".json`, and name the .json where the model file was named");
  LoadedModel m = readDescription(desc, options);
  m.file = path;  // the runs and errors name the lab's model file, as natively
  return m;
}

}  // namespace dyn::app
