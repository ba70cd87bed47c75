// dynlab's own elements beside a model file (a rolling wheel, a ball against a plane) onto the
// description, after the file's closures: see model_file.h (GivenRolling, GivenContact). Each is the
// constraint kind a lab's C++ writes (physics/constraints/rolling.h, plane_contact.h), its points moved
// from the MuJoCo body's frame into the tree body's (on its joint's anchor, world-aligned at q0).
#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>

#include "physics/constraints/plane_contact.h"
#include "physics/constraints/rolling.h"
#include "physics/model_file/mujoco_call.h"
#include "physics/model_file/number_text.h"

namespace dyn::model_file::detail {
namespace {

using Vec3 = Eigen::Vector3d;
using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

std::string num(double x) { return detail::numberText(x, 6); }

// The place of an element's body: its MuJoCo body's pose at q0 and the tree body it moves with.
struct Place {
  int link = -1;
  Vec3 origin, x;  // the tree body's frame origin, the MuJoCo body's (world, q0)
  Eigen::Matrix3d R;  // the MuJoCo body's axes (world, q0)
  Vec3 world(const Vec3& p) const { return x + R * p; }
};

Place place(const std::string& path, const mjModel* m, const mjData* d, const std::vector<int>& link,
            const std::vector<Vec3>& origin, const std::string& where, const std::string& name) {
  const int b = name == "world" ? 0 : mj_name2id(m, mjOBJ_BODY, name.c_str());
  if (b < 0)
    throw ModelFileError(where + ".body: expected a body (link) of " + path + ", got '" + name +
                         "' (a link fixed to its parent is fused into it by MuJoCo: name the parent, with the point in its frame)");
  if (link[std::size_t(b)] < 0)
    throw ModelFileError(where + ".body: '" + name + "' does not move (no joint between it and the world); expected a moving body");
  Place p;
  p.link = link[std::size_t(b)];
  p.origin = origin[std::size_t(b)];
  p.x = Vec3(d->xpos + 3 * b);
  p.R = Eigen::Map<const RowMat3>(d->xmat + 9 * b);
  return p;
}

}  // namespace

void addElements(const std::string& path, const mjModel* m, const mjData* d, const std::vector<int>& link,
                 const std::vector<Vec3>& origin, const LoadOptions& options, LoadedModel& out) {
  MechanismModel<Spatial>& mech = out.mechanism;
  // Names head the trace's columns: one per closure, wheel and contact.
  std::set<std::string> names;
  for (const Closure& c : out.closures) names.insert(c.name);
  auto fresh = [&](const std::string& where, const std::string& name) {
    if (!names.insert(name).second) throw ModelFileError(where + ".name: '" + name + "' names another closure, wheel or contact too (expected a new name)");
  };
  for (const GivenRolling& g : options.rolling) {
    fresh(g.where, g.name);
    const Place p = place(path, m, d, link, origin, g.where, g.body);
    const Vec3 c = p.world(g.centre), a = p.R * g.axle;
    if (!(a.norm() > 0)) throw ModelFileError(g.where + ".axle: expected a non-zero direction");
    // The rim's lowest point at q0 (rolling.h: d = u/|u|, u = ẑ − (ẑ·a) a) must stand on the ground.
    const Vec3 an = a.normalized(), u = Vec3::UnitZ() - an.z() * an;
    const Vec3 P = c - g.radius * (u.norm() > 1e-9 ? Vec3(u.normalized()) : Vec3::UnitZ());
    if (!(std::abs(P.z() - g.height) <= 1e-9))
      throw ModelFileError(g.where + " ('" + g.name + "'): the wheel's lowest point is at z = " + num(P.z()) + " m at the reference pose, not on its ground z = " +
                           num(g.height) + " m; write the file with the wheel on the ground");
    try {
      mech.constraints.push_back(std::make_shared<Rolling>(BodyRef::link(p.link), c - p.origin, a, g.radius, g.height, g.mu));
    } catch (const std::invalid_argument& e) {
      throw ModelFileError(g.where + " ('" + g.name + "'): " + e.what());
    }
    out.contacts.push_back({g.name, "rolling", g.body, p.link, g.mu});
  }
  for (const GivenContact& g : options.contacts) {
    fresh(g.where, g.name);
    const Place p = place(path, m, d, link, origin, g.where, g.body);
    const Vec3 c = p.world(g.point);
    if (!(g.normal.norm() > 0)) throw ModelFileError(g.where + ".normal: expected a non-zero direction");
    // A rigid contact may not start inside its plane (a compliant one may: it pushes out).
    const double gap = g.normal.normalized().dot(c) - g.radius - g.height;
    if (g.stiffness == 0 && !(gap >= -1e-9))
      throw ModelFileError(g.where + " ('" + g.name + "'): the ball starts " + num(-gap) + " m inside its plane at the reference pose; expected it on or above the plane");
    PlaneContactParams params;
    params.radius = g.radius, params.height = g.height, params.mu = g.mu, params.stiffness = g.stiffness, params.damping = g.damping;
    try {
      mech.constraints.push_back(std::make_shared<PlaneContact<Spatial>>(BodyRef::link(p.link), c - p.origin, g.normal, params));
    } catch (const std::invalid_argument& e) {
      throw ModelFileError(g.where + " ('" + g.name + "'): " + e.what());
    }
    out.contacts.push_back({g.name, "plane_contact", g.body, p.link, g.mu});
  }
  if (const std::string why = mech.validate(); !why.empty()) throw ModelFileError(path + ": " + why);
}

}  // namespace dyn::model_file::detail
