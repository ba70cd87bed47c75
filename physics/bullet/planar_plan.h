// The plan of a planar Bullet model (Eigen only, no Bullet): which Bullet links, joints and constraints
// realise a mechanism description (physics/mechanism.h), and the planar kinematics of that tree.
//
// Unilateral constraints (plane_contact) take no part in the plan: bullet_mechanism.cpp makes them
// contacts (contact_balls.h). Spanning tree (Kruskal over the description's bodies, then rooted at the
// world by breadth-first order):
//   edges in priority order  payload guides (world → payload), tree joints not in cut_joints, welds
//   (attachments holding all of ω, x, y). An edge joining two separate components becomes a Bullet
//   joint; every other edge, and every point attachment (x, y only), becomes a Bullet constraint.
// Bullet link frames. Each link's frame sits at its centre of mass, oriented like the description
// body's frame (a payload's frame is its centre of mass at angle ψ). At Bullet coordinate q a link is
//   φ = φ_parent + δ (+ q, revolute),   c = c_parent + R(φ_parent) e + R(φ) (d (+ q axis, prismatic))
// with e (parent frame) from the parent's centre of mass to the pivot, d (own frame) from the pivot to
// its centre of mass, δ its angle in the parent at q = 0. Bullet's zero is the description's zero
// (θ = 0, payload pose with its free coordinates 0), so q = sign × (description coordinate).
// Joints traversed child → parent have sign −1 (Bullet's parent is the description's child).
// Floating parts. A payload with all three coordinates free, and the root link of every part of the
// trees that cutting leaves without a path to the world, hang from the world by massless guide links
// (prismatic x, prismatic y, revolute ψ at the body's centre of mass): one fixed-base btMultiBody
// carries everything. A floating link's guide coordinates are not description coordinates: they are
// set from the description's pose of that link at q0 (descriptionMotion) and read back as poses.
#pragma once
#include <Eigen/Core>
#include <string>
#include <vector>

#include "physics/mechanism.h"

namespace dyn::bullet {

inline constexpr int kWorldLink = -1;  // Bullet's fixed base is the world (identity pose)

struct PlanLink {
  enum class Joint { Revolute, Prismatic, Fixed };
  Joint joint = Joint::Fixed;
  int parent = kWorldLink;                         // Bullet link index (parents come first)
  double mass = 0, inertia = 0;                    // about the centre of mass (0: a massless guide link)
  double delta = 0;                                // frame angle in the parent's frame at q = 0
  Eigen::Vector2d e = Eigen::Vector2d::Zero();     // parent's centre of mass → pivot, parent frame
  Eigen::Vector2d d = Eigen::Vector2d::Zero();     // pivot → own centre of mass, own frame
  Eigen::Vector2d axis = Eigen::Vector2d::Zero();  // prismatic: unit axis, own frame
  BodyRef body;                                    // the description body it is (World: guide link)
  int coord = -1;                                  // description coordinate it moves (−1: fixed)
  double sign = 1;                                 // q_bullet = sign × coordinate
  int tree_joint = -1;                             // description tree joint it realises (−1: none)
  int floating = -1;                               // guide of floating tree body `floating`
  int floating_axis = -1;                          //   along its centre of mass x (0), y (1) or angle (2)
  int weld = -1;                                   // description constraint it realises (fixed joint)
};

// A Bullet multibody constraint between two links (kWorldLink: the world, pivot in world coordinates):
// a point-to-point, or for a weld that closes a loop a btMultiBodyFixedConstraint (frames aligned).
struct PlanConstraint {
  enum class Kind { Point, Weld };
  Kind kind = Kind::Point;
  int link_a = kWorldLink, link_b = kWorldLink;
  Eigen::Vector2d pivot_a = Eigen::Vector2d::Zero(), pivot_b = Eigen::Vector2d::Zero();  // COM frames
  int constraint = -1;  // description constraint it realises, or −1
  int cut_joint = -1;   // description tree joint it realises (a cut revolute joint), or −1
  double sign = 1;      // +1 if Bullet's A is the description's body a (the force then acts +λ on b)
};

struct Plan {
  std::vector<PlanLink> links;
  std::vector<PlanConstraint> constraints;
  std::vector<int> link_of_tree_body;  // Bullet link of each TreeModel body
  std::vector<int> link_of_payload;    // Bullet link carrying each payload
  std::vector<int> cut_joints;         // description joints realised as constraints
  std::vector<int> constraint_of;      // per description constraint: index into constraints, or −1
  std::vector<int> weld_link;          // per description constraint: its fixed Bullet link, or −1
  std::vector<double> tree_angle;      // per tree joint: angle of X_tree
  Eigen::Vector2d gravity = Eigen::Vector2d::Zero();
  int coordinates = 0;                 // n + k
  std::string summary;                 // how it was grown, for describe()
};

// Grows the plan; throws std::invalid_argument naming what it cannot model.
Plan makePlan(const MechanismModel<Planar>& model);

// World pose and motion of every Bullet link (centre of mass), from Bullet coordinates.
struct LinkMotion {
  double phi = 0, omega = 0, alpha = 0;
  Eigen::Vector2d c = Eigen::Vector2d::Zero(), v = Eigen::Vector2d::Zero(), a = Eigen::Vector2d::Zero();
};
// q, qd, qdd: one value per link (fixed links ignored); qdd may be null (accelerations left 0).
void planarKinematics(const Plan& plan, const std::vector<double>& q, const std::vector<double>& qd,
                      const std::vector<double>* qdd, std::vector<LinkMotion>& out);

// World pose and motion (centre of mass) of every TreeModel body at description state (q, v).
void descriptionMotion(const MechanismModel<Planar>& model, const VecN& q, const VecN& v,
                       std::vector<LinkMotion>& out);

Eigen::Vector2d rotate(double angle, const Eigen::Vector2d& v);
inline Eigen::Vector2d perp(const Eigen::Vector2d& v) { return {-v.y(), v.x()}; }  // ẑ × v
inline double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

}  // namespace dyn::bullet
