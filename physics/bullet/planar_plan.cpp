// The plan of a planar Bullet model: spanning tree, link geometry and constraints (see planar_plan.h).
// Geometry of each kind of tree edge, P = Bullet parent, C = Bullet child, c_B a body's centre of mass
// in its frame, X_tree = (angle β, origin r) the joint frame of tree joint i in its parent's frame:
//   joint i, forward  (P = parent, C = i)   e = r − c_P,  d = c_i,      δ = β,  q = +θ_i
//   joint i, reversed (P = i, C = parent)   e = −c_i,     d = c_P − r,  δ = −β, q = −θ_i
//                                           (prismatic axis, in C's frame: R(β) axis)
//   weld (a held on b, frames aligned)      e = p_P − c_P, d = c_C − p_C, δ = 0 (a weld left out of
//                                           the tree: a btMultiBodyFixedConstraint)
//   payload guide (world → payload)         pivot at pose0 with the free coordinate set to 0, q = it
// Unilateral constraints (plane_contact) are neither: the builder models them as contacts.
#include "physics/bullet/planar_plan.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <numeric>
#include <sstream>
#include <stdexcept>

namespace dyn::bullet {

Eigen::Vector2d rotate(double angle, const Eigen::Vector2d& v) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}

namespace {

using Vec2 = Eigen::Vector2d;

// A tree edge candidate between two description bodies (graph nodes: world 0, links, payloads).
struct Edge {
  enum class Type { Guide, Joint, Weld } type;
  int index;  // payload, tree joint or constraint index
  int u, v;   // nodes; for a joint u = parent, v = child; for a weld u = a, v = b
};

struct Builder {
  const MechanismModel<Planar>& m;
  int n = 0;
  Plan plan;
  std::vector<Edge> edges;
  std::vector<char> in_tree;
  int floating = 0;

  explicit Builder(const MechanismModel<Planar>& model) : m(model), n(model.tree.dof()) {}

  int node(const BodyRef& b) const {
    if (b.kind == BodyRef::Kind::Link) return 1 + b.index;
    if (b.kind == BodyRef::Kind::Payload) return 1 + n + b.index;
    return 0;
  }
  BodyRef body(int node) const {
    if (node == 0) return BodyRef::world();
    return node <= n ? BodyRef::link(node - 1) : BodyRef::payload(node - 1 - n);
  }
  std::string name(const BodyRef& b) const {
    if (b.kind == BodyRef::Kind::Link) return "tree body " + std::to_string(b.index);
    if (b.kind == BodyRef::Kind::Payload) {
      const auto& p = m.payloads[std::size_t(b.index)];
      return "payload " + std::to_string(b.index) + (p.name.empty() ? "" : " (" + p.name + ")");
    }
    return "the world";
  }
  // Centre of mass in the body's frame, mass and inertia about it.
  Vec2 com(const BodyRef& b) const {
    if (b.kind != BodyRef::Kind::Link) return Vec2::Zero();
    double mass;
    Vec2 c;
    Planar::massAndCom(m.tree.bodies[std::size_t(b.index)].inertia, mass, c);
    return c;
  }
  void massOf(const BodyRef& b, double& mass, double& inertia) const {
    if (b.kind == BodyRef::Kind::Payload) {
      mass = m.payloads[std::size_t(b.index)].mass;
      inertia = m.payloads[std::size_t(b.index)].inertia;
    } else if (b.kind == BodyRef::Kind::Link) {
      const auto& I = m.tree.bodies[std::size_t(b.index)].inertia;
      const Vec2 c = com(b);
      mass = I(1, 1);
      inertia = I(0, 0) - mass * c.squaredNorm();
    } else {
      mass = inertia = 0;
    }
  }
  void checkBody(const BodyRef& b, const std::string& what) const {
    const bool ok = b.kind == BodyRef::Kind::World ||
                    (b.kind == BodyRef::Kind::Link && b.index >= 0 && b.index < n) ||
                    (b.kind == BodyRef::Kind::Payload && b.index >= 0 && b.index < int(m.payloads.size()));
    if (!ok) throw std::invalid_argument("BulletMechanism: " + what + " names a body that does not exist");
  }

  void collectEdges() {
    for (int j = 0; j < int(m.payloads.size()); ++j) {
      const auto& f = m.payloads[std::size_t(j)].free;
      const int k = m.payloads[std::size_t(j)].dof();
      const bool ok = (k == 1) || (f[0] && f[1] && f[2]);
      if (!ok)
        throw std::invalid_argument("BulletMechanism: " + name(BodyRef::payload(j)) + " has free = {" +
                                    (f[0] ? "ψ" : "") + (f[1] ? " x" : "") + (f[2] ? " y" : "") +
                                    " }: only one free coordinate (a guide) or all three are supported");
      edges.push_back({Edge::Type::Guide, j, 0, node(BodyRef::payload(j))});
    }
    for (int c : m.bullet.cut_joints)
      if (c < 0 || c >= n)
        throw std::invalid_argument("BulletMechanism: cut joint " + std::to_string(c) + " is not a tree joint");
    for (int i = 0; i < n; ++i) {
      const int p = m.tree.bodies[std::size_t(i)].parent;
      if (p >= i) throw std::invalid_argument("BulletMechanism: tree body " + std::to_string(i) + "'s parent must come first");
      const bool cut = std::find(m.bullet.cut_joints.begin(), m.bullet.cut_joints.end(), i) != m.bullet.cut_joints.end();
      if (!cut) edges.push_back({Edge::Type::Joint, i, p < 0 ? 0 : 1 + p, 1 + i});
    }
    for (int c = 0; c < int(m.constraints.size()); ++c) {
      if (m.constraints[std::size_t(c)]->unilateral()) continue;  // a contact: no joint, no constraint (bullet_mechanism.cpp)
      const std::string what = "constraint " + std::to_string(c) + " (" + m.constraints[std::size_t(c)]->kind() + ")";
      const Attachment<Planar> at = m.constraints[std::size_t(c)]->attachment();
      checkBody(at.a, what);
      checkBody(at.b, what);
      if (at.a == at.b) throw std::invalid_argument("BulletMechanism: " + what + " attaches a body to itself");
      const auto& r = at.rows;
      const bool weld = r[0] && r[1] && r[2], point = !r[0] && r[1] && r[2];
      if (!weld && !point)
        throw std::invalid_argument("BulletMechanism: " + what + " holds rows {" + (r[0] ? "ω" : "") +
                                    (r[1] ? " x" : "") + (r[2] ? " y" : "") +
                                    " }: only {ω, x, y} (weld) and {x, y} (point) are supported");
      if (weld) edges.push_back({Edge::Type::Weld, c, node(at.a), node(at.b)});
    }
  }

  // Kruskal in priority order (the edges were collected guides, joints, welds).
  void spanningTree() {
    std::vector<int> root(std::size_t(1 + n + int(m.payloads.size())));
    std::iota(root.begin(), root.end(), 0);
    auto find = [&](int x) {
      while (root[std::size_t(x)] != x) x = root[std::size_t(x)] = root[std::size_t(root[std::size_t(x)])];
      return x;
    };
    in_tree.assign(edges.size(), 0);
    for (std::size_t k = 0; k < edges.size(); ++k) {
      const int a = find(edges[k].u), b = find(edges[k].v);
      if (a != b) root[std::size_t(a)] = b, in_tree[k] = 1;
    }
  }

  int addLink(PlanLink l) {
    plan.links.push_back(l);
    return int(plan.links.size()) - 1;
  }

  // Massless prismatic x then y from the world; returns the y link (the ψ link hangs from it).
  int addPlanarGuide(int coord_x, int coord_y, int floating) {
    PlanLink x, y;
    x.joint = y.joint = PlanLink::Joint::Prismatic;
    x.axis = Vec2::UnitX(), x.coord = coord_x, x.floating = floating, x.floating_axis = 0;
    y.parent = addLink(x);
    y.axis = Vec2::UnitY(), y.coord = coord_y, y.floating = floating, y.floating_axis = 1;
    return addLink(y);
  }
  // A tree body with no path to the world: floating on a planar guide, revolute at its centre of mass.
  int addFloating(int i) {
    PlanLink l;
    l.parent = addPlanarGuide(-1, -1, i);
    l.joint = PlanLink::Joint::Revolute, l.body = BodyRef::link(i), l.floating = i, l.floating_axis = 2;
    massOf(l.body, l.mass, l.inertia);
    ++floating;
    return addLink(l);
  }

  // The payload's guide from the world: its free coordinate(s) as Bullet joints.
  int addGuide(int j) {
    const Payload& p = m.payloads[std::size_t(j)];
    const int off = n + m.payloadOffset(j);
    PlanLink l;
    l.body = BodyRef::payload(j);
    l.mass = p.mass;
    l.inertia = p.inertia;
    const double psi = p.pose0[0];
    if (p.dof() == 3) {  // x, y (massless guide links), then ψ on the payload itself
      l.parent = addPlanarGuide(off + 1, off + 2, -1);
      l.joint = PlanLink::Joint::Revolute, l.coord = off;
    } else if (p.free[0]) {
      l.joint = PlanLink::Joint::Revolute, l.e = p.pose0.tail<2>(), l.coord = off;
    } else {
      const int k = p.free[1] ? 0 : 1;  // the free world axis
      l.joint = PlanLink::Joint::Prismatic, l.delta = psi, l.coord = off;
      l.e = p.pose0.tail<2>(), l.e[k] = 0;
      l.axis = rotate(-psi, Vec2::Unit(k));
    }
    return addLink(l);
  }

  // Tree joint i from Bullet link `from` (its description parent or child) to the other body.
  int addJoint(int i, int from_node, int parent_link) {
    const auto& tb = m.tree.bodies[std::size_t(i)];
    const double beta = plan.tree_angle[std::size_t(i)];
    const BodyRef child = BodyRef::link(i), parent = tb.parent < 0 ? BodyRef::world() : BodyRef::link(tb.parent);
    const bool forward = from_node != 1 + i;
    PlanLink l;
    l.parent = parent_link;
    l.joint = tb.joint == JointType::Revolute ? PlanLink::Joint::Revolute : PlanLink::Joint::Prismatic;
    l.coord = i, l.tree_joint = i;
    l.body = forward ? child : parent;
    massOf(l.body, l.mass, l.inertia);
    if (forward) {
      l.e = tb.X_tree.r - com(parent), l.d = com(child), l.delta = beta, l.sign = 1, l.axis = tb.axis;
    } else {
      l.e = -com(child), l.d = com(parent) - tb.X_tree.r, l.delta = -beta, l.sign = -1;
      l.axis = rotate(beta, tb.axis);
    }
    if (l.joint == PlanLink::Joint::Prismatic) l.axis.normalize();
    return addLink(l);
  }

  // Weld constraint c: the body not yet placed is welded to the one placed (frames aligned).
  int addWeld(int c, int from_node, int parent_link) {
    const Attachment<Planar> at = m.constraints[std::size_t(c)]->attachment();
    const bool a_first = node(at.a) == from_node;
    const BodyRef P = a_first ? at.a : at.b, C = a_first ? at.b : at.a;
    const Vec2 pP = a_first ? at.point_a : at.point_b, pC = a_first ? at.point_b : at.point_a;
    PlanLink l;
    l.parent = parent_link, l.body = C, l.weld = c;
    massOf(C, l.mass, l.inertia);
    l.e = pP - com(P), l.d = com(C) - pC;
    return addLink(l);
  }

  // Root the chosen edges at the world, breadth first, parents before children.
  void growLinks() {
    const int nodes = 1 + n + int(m.payloads.size());
    std::vector<int> link_of(std::size_t(nodes), -2);
    link_of[0] = kWorldLink;
    std::deque<int> queue{0};
    for (int next = 1;;) {
      // A part left without a path to the world floats from its first body (payloads never do).
      if (queue.empty()) {
        while (next < nodes && link_of[std::size_t(next)] != -2) ++next;
        if (next >= nodes) break;
        link_of[std::size_t(next)] = addFloating(next - 1);
        queue.push_back(next);
      }
      const int u = queue.front();
      queue.pop_front();
      for (std::size_t k = 0; k < edges.size(); ++k) {
        const Edge& e = edges[k];
        if (!in_tree[k] || (e.u != u && e.v != u)) continue;
        const int w = e.u == u ? e.v : e.u;
        if (link_of[std::size_t(w)] != -2) continue;
        const int pl = link_of[std::size_t(u)];
        if (e.type == Edge::Type::Guide) link_of[std::size_t(w)] = addGuide(e.index);
        else if (e.type == Edge::Type::Joint) link_of[std::size_t(w)] = addJoint(e.index, u, pl);
        else link_of[std::size_t(w)] = plan.weld_link[std::size_t(e.index)] = addWeld(e.index, u, pl);
        queue.push_back(w);
      }
    }
    plan.link_of_tree_body.assign(link_of.begin() + 1, link_of.begin() + 1 + n);
    plan.link_of_payload.assign(link_of.begin() + 1 + n, link_of.end());
  }

  int linkOf(const BodyRef& b) const {
    if (b.kind == BodyRef::Kind::Link) return plan.link_of_tree_body[std::size_t(b.index)];
    if (b.kind == BodyRef::Kind::Payload) return plan.link_of_payload[std::size_t(b.index)];
    return kWorldLink;
  }

  // Everything left out of the tree becomes a Bullet constraint.
  void addConstraints() {
    for (std::size_t k = 0; k < edges.size(); ++k)
      if (edges[k].type == Edge::Type::Joint && !in_tree[k]) cutJoint(edges[k].index);
    for (int c : m.bullet.cut_joints) cutJoint(c);
    for (int c = 0; c < int(m.constraints.size()); ++c) {
      if (plan.weld_link[std::size_t(c)] >= 0 || m.constraints[std::size_t(c)]->unilateral()) continue;
      const Attachment<Planar> at = m.constraints[std::size_t(c)]->attachment();
      PlanConstraint pc;
      pc.kind = at.rows[0] ? PlanConstraint::Kind::Weld : PlanConstraint::Kind::Point;
      const bool swap = at.a.isWorld();  // Bullet's A must be a link
      pc.link_a = linkOf(swap ? at.b : at.a), pc.link_b = linkOf(swap ? at.a : at.b);
      pc.pivot_a = (swap ? at.point_b : at.point_a) - com(swap ? at.b : at.a);
      pc.pivot_b = (swap ? at.point_a : at.point_b) - com(swap ? at.a : at.b);
      pc.constraint = c, pc.sign = swap ? -1 : 1;
      plan.constraint_of[std::size_t(c)] = int(plan.constraints.size());
      plan.constraints.push_back(pc);
    }
  }
  // A cut revolute joint: child's joint point held on the parent's (a point-to-point).
  void cutJoint(int i) {
    const auto& tb = m.tree.bodies[std::size_t(i)];
    if (tb.joint != JointType::Revolute)
      throw std::invalid_argument("BulletMechanism: tree joint " + std::to_string(i) +
                                  " is prismatic and left out of Bullet's tree: cutting prismatic joints is not supported");
    if (std::find(plan.cut_joints.begin(), plan.cut_joints.end(), i) != plan.cut_joints.end()) return;
    const BodyRef parent = tb.parent < 0 ? BodyRef::world() : BodyRef::link(tb.parent);
    PlanConstraint pc;
    pc.link_a = linkOf(BodyRef::link(i)), pc.link_b = linkOf(parent);
    pc.pivot_a = -com(BodyRef::link(i)), pc.pivot_b = tb.X_tree.r - com(parent);
    pc.cut_joint = i;
    plan.cut_joints.push_back(i);
    plan.constraints.push_back(pc);
  }

  void summarise() {
    std::ostringstream s;
    s << "Bullet 3.24 btMultiBody (" << plan.links.size() << " links) grown from the world";
    if (!plan.cut_joints.empty()) {
      s << ", cut at joint";
      for (std::size_t k = 0; k < plan.cut_joints.size(); ++k) s << (k ? ", " : " ") << plan.cut_joints[k] + 1;
    }
    int welds = 0, points = 0;
    for (int w : plan.weld_link) welds += w >= 0;
    for (const auto& c : plan.constraints) points += c.cut_joint < 0;
    if (floating) s << ", " << floating << " floating part(s) on planar guides";
    if (welds) s << ", " << welds << " weld(s) as fixed joints";
    const int loop_welds = int(std::count_if(plan.constraints.begin(), plan.constraints.end(),
                                             [](const PlanConstraint& c) { return c.kind == PlanConstraint::Kind::Weld; }));
    if (points - loop_welds) s << ", " << points - loop_welds << " point-to-point constraint(s)";
    if (loop_welds) s << ", " << loop_welds << " btMultiBodyFixedConstraint(s)";
    s << ", PGS " << m.bullet.solver_iterations << " iterations";
    plan.summary = s.str();
  }

  Plan build() {
    plan.tree_angle.resize(std::size_t(n));
    for (int i = 0; i < n; ++i) {
      const auto& E = m.tree.bodies[std::size_t(i)].X_tree.E;
      plan.tree_angle[std::size_t(i)] = std::atan2(E(0, 1), E(0, 0));
    }
    plan.gravity = m.tree.gravity.tail<2>();
    plan.coordinates = n + m.payloadDof();
    plan.constraint_of.assign(m.constraints.size(), -1);
    plan.weld_link.assign(m.constraints.size(), -1);
    collectEdges();
    spanningTree();
    growLinks();
    addConstraints();
    summarise();
    return std::move(plan);
  }
};

}  // namespace

Plan makePlan(const MechanismModel<Planar>& model) { return Builder(model).build(); }

void descriptionMotion(const MechanismModel<Planar>& model, const VecN& q, const VecN& v,
                       std::vector<LinkMotion>& out) {
  const int n = model.tree.dof();
  std::vector<LinkMotion> origin(static_cast<std::size_t>(n));  // body frame origins (c, v) and angles
  out.resize(std::size_t(n));
  const LinkMotion world;
  for (int i = 0; i < n; ++i) {
    const auto& b = model.tree.bodies[std::size_t(i)];
    const LinkMotion& p = b.parent < 0 ? world : origin[std::size_t(b.parent)];
    const auto& E = b.X_tree.E;
    const bool rev = b.joint == JointType::Revolute;
    LinkMotion& o = origin[std::size_t(i)];
    // Joint frame at the parent's X_tree, then the joint's own rotation or slide.
    o.phi = p.phi + std::atan2(E(0, 1), E(0, 0)) + (rev ? q[i] : 0.0);
    o.omega = p.omega + (rev ? v[i] : 0.0);
    const Vec2 r = rotate(p.phi, b.X_tree.r);
    const Vec2 slide = rev ? Vec2::Zero() : rotate(o.phi, b.axis.normalized());
    o.c = p.c + r + slide * q[i];
    o.v = p.v + p.omega * perp(r) + o.omega * perp(slide) * q[i] + slide * v[i];
    // Its centre of mass.
    double m;
    Vec2 c;
    Planar::massAndCom(b.inertia, m, c);
    const Vec2 rc = rotate(o.phi, c);
    out[std::size_t(i)] = o;
    out[std::size_t(i)].c = o.c + rc;
    out[std::size_t(i)].v = o.v + o.omega * perp(rc);
  }
}

void planarKinematics(const Plan& plan, const std::vector<double>& q, const std::vector<double>& qd,
                      const std::vector<double>* qdd, std::vector<LinkMotion>& out) {
  out.resize(plan.links.size());
  const LinkMotion world;
  for (std::size_t k = 0; k < plan.links.size(); ++k) {
    const PlanLink& l = plan.links[k];
    const LinkMotion& p = l.parent < 0 ? world : out[std::size_t(l.parent)];
    LinkMotion& o = out[k];
    const bool rev = l.joint == PlanLink::Joint::Revolute, pri = l.joint == PlanLink::Joint::Prismatic;
    const double qk = q[k], vk = qd[k], ak = qdd ? (*qdd)[k] : 0.0;
    // Orientation and angular motion: revolute adds its coordinate.
    o.phi = p.phi + l.delta + (rev ? qk : 0.0);
    o.omega = p.omega + (rev ? vk : 0.0);
    o.alpha = p.alpha + (rev ? ak : 0.0);
    // Parent COM → pivot (parent frame), pivot → own COM (own frame, prismatic slides along axis).
    const Vec2 r1 = rotate(p.phi, l.e);
    const Vec2 r2 = rotate(o.phi, pri ? Vec2(l.d + qk * l.axis) : l.d);
    const Vec2 slide = pri ? rotate(o.phi, l.axis) : Vec2::Zero();
    o.c = p.c + r1 + r2;
    o.v = p.v + p.omega * perp(r1) + o.omega * perp(r2) + slide * vk;
    o.a = p.a + p.alpha * perp(r1) - p.omega * p.omega * r1 + o.alpha * perp(r2) - o.omega * o.omega * r2 +
          2.0 * o.omega * perp(slide) * vk + slide * ak;
  }
}

}  // namespace dyn::bullet
