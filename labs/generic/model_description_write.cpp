// A loaded model as dynlab's description (model_description.h): plain JSON, each double as nlohmann
// writes it (the shortest text that reads back to the same bits), matrices row by row.
#include <filesystem>
#include <map>

#include "labs/generic/model_description.h"
#include "physics/constraints/coupling.h"
#include "physics/constraints/joint_limit.h"
#include "physics/constraints/plane_contact.h"
#include "physics/constraints/point_closure.h"
#include "physics/constraints/rolling.h"

namespace dyn::app {
namespace {

using model_file::ModelFileError;

template <class M>
json numbers(const M& m) {  // row by row
  json a = json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) a.push_back(double(m(r, c)));
  return a;
}

int linkOf(const BodyRef& b, const std::string& file) {
  if (b.kind == BodyRef::Kind::Payload) throw ModelFileError(file + ": a payload body; a description holds a model file's trees only");
  return b.isWorld() ? -1 : b.index;
}

json formJson(const Coupling::Form& f) {
  json a = json::array();
  for (const Coupling::Term& t : f) a.push_back({{"joint", t.joint}, {"coef", t.coef}});
  return a;
}

json constraintJson(const Constraint<Spatial>& c, const std::string& file) {
  if (const auto* p = dynamic_cast<const PointClosure<Spatial>*>(&c)) {
    const Attachment<Spatial> at = p->attachment();
    json rows = json::array();
    for (bool r : at.rows) rows.push_back(r);
    return {{"kind", "point_closure"}, {"a", linkOf(at.a, file)}, {"point_a", numbers(at.point_a)}, {"b", linkOf(at.b, file)},
            {"point_b", numbers(at.point_b)}, {"rows", rows}};
  }
  if (const auto* l = dynamic_cast<const JointLimit*>(&c))
    return {{"kind", "joint_limit"}, {"joint", l->joint()}, {"parent", linkOf(l->attachment().a, file)},
            {"side", l->side() == JointLimit::Side::Lower ? "lower" : "upper"}, {"bound", l->bound()}};
  if (const auto* k = dynamic_cast<const Coupling*>(&c)) {
    json poly = json::array();
    for (double x : k->poly()) poly.push_back(x);
    return {{"kind", k->kind()}, {"first", formJson(k->first())}, {"second", formJson(k->second())}, {"poly", poly},
            {"reference", numbers(k->reference())}};
  }
  if (const auto* w = dynamic_cast<const Rolling*>(&c))
    return {{"kind", "rolling"}, {"wheel", linkOf(w->wheel(), file)}, {"centre", numbers(w->centre())}, {"axle", numbers(w->axle())},
            {"radius", w->radius()}, {"ground", w->groundHeight()}, {"mu", w->mu()}};
  if (const auto* p = dynamic_cast<const PlaneContact<Spatial>*>(&c)) {
    const PlaneContactParams& q = p->params();
    return {{"kind", "plane_contact"}, {"body", linkOf(p->body(), file)}, {"centre", numbers(p->centre())}, {"normal", numbers(p->normal())},
            {"radius", q.radius}, {"height", q.height}, {"mu", q.mu}, {"stiffness", q.stiffness}, {"damping", q.damping}};
  }
  throw ModelFileError(file + ": a constraint of kind '" + c.kind() + "', which a description does not hold");
}

const char* jointName(JointType t) { return t == JointType::Revolute ? "revolute" : t == JointType::Prismatic ? "prismatic" : "ball"; }

json treeJson(const TreeModel<Spatial>& tree) {
  json bodies = json::array(), balls = json::array();
  for (const auto& b : tree.bodies)
    bodies.push_back({{"parent", b.parent}, {"joint", jointName(b.joint)}, {"axis", numbers(b.axis)}, {"E", numbers(b.X_tree.E)},
                      {"r", numbers(b.X_tree.r)}, {"inertia", numbers(b.inertia)}});
  for (const auto& b : tree.balls) balls.push_back({{"first", b.first}, {"pre", numbers(b.pre)}, {"post", numbers(b.post)}});
  return {{"gravity", numbers(tree.gravity)}, {"bodies", bodies}, {"balls", balls}};
}

json mechanismJson(const MechanismModel<Spatial>& mech, const std::string& file) {
  if (!mech.payloads.empty() || !mech.forces.empty())
    throw ModelFileError(file + ": payloads or external forces; a description holds a model file's trees and constraints only");
  json joints = json::array(), constraints = json::array(), cut = json::array();
  for (const JointProperties& p : mech.joints)
    joints.push_back({{"stiffness", p.stiffness}, {"rest", p.rest}, {"viscous", p.viscous}, {"coulomb", p.coulomb},
                      {"coulomb_width", p.coulomb_width}, {"armature", p.armature}});
  for (const auto& c : mech.constraints) constraints.push_back(constraintJson(*c, file));
  for (int j : mech.bullet.cut_joints) cut.push_back(j);
  return {{"tree", treeJson(mech.tree)}, {"joints", joints}, {"constraints", constraints},
          {"bullet", {{"cut_joints", cut}, {"solver_iterations", mech.bullet.solver_iterations},
                      {"rolling", mech.bullet.rolling == RollingModel::NoSlip ? "no_slip" : "friction"}}}};
}

json pathJson(const std::vector<model_file::TendonTerm>& path) {
  json a = json::array();
  for (const auto& t : path) a.push_back({{"coordinate", t.coordinate}, {"coef", t.coef}, {"qpos", t.qpos}});
  return a;
}

json actuatorsJson(const model_file::LoadedModel& m) {
  json a = json::array();
  for (const auto& x : m.actuators)
    a.push_back({{"name", x.name}, {"joint", x.joint}, {"tendon", x.tendon}, {"path", pathJson(x.path)}, {"gear", x.gear}, {"gain", x.gain},
                 {"bias", {x.bias[0], x.bias[1], x.bias[2]}}, {"ctrl_limited", x.ctrl_limited}, {"force_limited", x.force_limited},
                 {"ctrl_range", {x.ctrl_lower, x.ctrl_upper}}, {"force_range", {x.force_lower, x.force_upper}}});
  return a;
}

json tendonsJson(const model_file::LoadedModel& m) {
  json a = json::array();
  for (const auto& t : m.tendons)
    a.push_back({{"name", t.name}, {"path", pathJson(t.path)}, {"stiffness", t.stiffness}, {"rest", t.rest}, {"damping", t.damping},
                 {"frictionloss", t.frictionloss}, {"friction_width", t.friction_width}});
  return a;
}

const char* shapeName(model_file::Geom::Shape s) {
  using S = model_file::Geom::Shape;
  switch (s) {
    case S::Sphere: return "sphere";
    case S::Capsule: return "capsule";
    case S::Cylinder: return "cylinder";
    case S::Box: return "box";
    case S::Plane: return "plane";
    case S::Mesh: return "mesh";
  }
  return "sphere";
}

// The geoms, the meshes they draw (each once, however many geoms share it) and the bones.
json drawingJson(const model_file::Drawing& d) {
  std::map<const TriangleMesh*, int> index;
  json geoms = json::array(), meshes = json::array(), bones = json::array();
  for (const auto& g : d.geoms) {
    json mesh = nullptr;
    if (g.mesh) {
      auto [it, added] = index.emplace(g.mesh.get(), int(index.size()));
      if (added) {
        json v = json::array(), t = json::array();
        for (const auto& p : g.mesh->vertices) v.push_back(numbers(p.transpose()));
        for (const auto& f : g.mesh->triangles) t.push_back({f[0], f[1], f[2]});
        meshes.push_back({{"vertices", v}, {"triangles", t}});
      }
      mesh = it->second;
    }
    geoms.push_back({{"shape", shapeName(g.shape)}, {"name", g.name}, {"body", g.body}, {"link", g.link}, {"pos", numbers(g.pos)},
                     {"rot", numbers(g.rot)}, {"size", numbers(g.size)}, {"mesh", mesh},
                     {"rgba", {double(g.rgba[0]), double(g.rgba[1]), double(g.rgba[2]), double(g.rgba[3])}}, {"file_color", g.file_color}});
  }
  for (const auto& b : d.bones) bones.push_back({{"link", b.link}, {"from", numbers(b.from)}, {"to", numbers(b.to)}});
  return {{"geoms", geoms}, {"meshes", meshes}, {"bones", bones}, {"notes", d.notes}};
}

json closuresJson(const model_file::LoadedModel& m) {
  json closures = json::array(), every = json::array();
  for (const auto& c : m.closures)
    closures.push_back({{"name", c.name}, {"kind", c.kind}, {"body1", c.body1}, {"body2", c.body2}, {"kept", c.kept}, {"dropped", c.dropped},
                        {"link1", c.link1}, {"link2", c.link2}, {"point1", numbers(c.point1)}, {"point2", numbers(c.point2)}});
  for (const auto& e : m.every_closure_row)
    every.push_back({{"name", e.name}, {"rows", constraintJson(*e.rows, m.file)}, {"dropped", e.dropped}});
  return {{"closures", closures}, {"every_closure_row", every}};
}

}  // namespace

json describeModel(const model_file::LoadedModel& m) {
  json joints = json::array(), contacts = json::array();
  for (const auto& j : m.joints)
    joints.push_back({{"name", j.name}, {"body", j.body}, {"type", j.type}, {"qpos", j.qpos}, {"limited", j.limited}, {"lower", j.lower},
                      {"upper", j.upper}});
  for (const auto& c : m.contacts)
    contacts.push_back({{"name", c.name}, {"kind", c.kind}, {"body", c.body}, {"link", c.link}, {"mu", c.mu}});
  const json loops = closuresJson(m);
  return {{"format", kDescriptionFormat},
          {"version", kDescriptionVersion},
          {"source", std::filesystem::path(m.file).filename().string()},
          {"timestep", m.timestep},
          {"dof", m.dof},
          {"q0", numbers(m.q0)},
          {"coordinates", m.coordinates},
          {"joints", joints},
          {"bodies", m.bodies},
          {"mechanism", mechanismJson(m.mechanism, m.file)},
          {"closures", loops["closures"]},
          {"every_closure_row", loops["every_closure_row"]},
          {"contacts", contacts},
          {"actuators", actuatorsJson(m)},
          {"tendons", tendonsJson(m)},
          {"keyframes", m.keyframes},
          {"start", {{"key", m.key}, {"q", numbers(m.start_q)}, {"v", numbers(m.start_v)}, {"ctrl", numbers(m.ctrl)}}},
          {"notes", m.notes},
          {"drawing", drawingJson(m.drawing)}};
}

std::string descriptionText(const model_file::LoadedModel& m) { return describeModel(m).dump(1) + "\n"; }

}  // namespace dyn::app
