// A planar tree as one bare btMultiBody (see bullet_chain.h).
#include "physics/bullet/bullet_chain.h"

#include <stdexcept>

#include "physics/bullet/bullet_world.h"
#include "physics/bullet/planar_multibody.h"
#include "physics/bullet/planar_plan.h"

namespace dyn::bullet {

struct BulletChain::Impl {
  TreeModel<Planar> tree;
  Plan plan;
  double dt;
  std::vector<Eigen::Vector2d> com;  // per tree body: centre of mass in its frame (Bullet's link origin)
  BulletWorld world;                 // before the body: destroyed after it
  std::unique_ptr<btMultiBody> body;

  static Plan planOf(const TreeModel<Planar>& tree, int iterations) {
    MechanismModel<Planar> m;
    m.tree = tree;
    m.bullet.solver_iterations = iterations;
    return makePlan(m);
  }

  Impl(const TreeModel<Planar>& t, double step, const Eigen::VectorXd& q0, const Eigen::VectorXd& v0)
      : tree(t), plan(planOf(t, 1)), dt(step), world(bt(plan.gravity), 1) {
    if (!(dt > 0.0)) throw std::invalid_argument("BulletChain: dt must be > 0");
    if (q0.size() != tree.dof() || v0.size() != tree.dof())
      throw std::invalid_argument("BulletChain: q0 and v0 need one value per joint (" + std::to_string(tree.dof()) + ")");
    for (const auto& b : tree.bodies) {
      double m;
      Eigen::Vector2d c;
      Planar::massAndCom(b.inertia, m, c);
      com.push_back(c);
    }
    body = makePlanarMultiBody(plan, *world.world);
    for (int i = 0; i < tree.dof(); ++i) {
      const PlanLink& l = plan.links[std::size_t(plan.link_of_tree_body[std::size_t(i)])];
      body->setJointPos(plan.link_of_tree_body[std::size_t(i)], l.sign * q0[i]);
      body->setJointVel(plan.link_of_tree_body[std::size_t(i)], l.sign * v0[i]);
    }
    btAlignedObjectArray<btQuaternion> w2l;
    btAlignedObjectArray<btVector3> origin;
    body->forwardKinematics(w2l, origin);
  }

  ~Impl() {
    if (body) world->removeMultiBody(body.get());
  }
};

BulletChain::BulletChain(const TreeModel<Planar>& tree, double dt, const Eigen::VectorXd& q0, const Eigen::VectorXd& v0)
    : impl_(std::make_unique<Impl>(tree, dt, q0, v0)) {}
BulletChain::~BulletChain() = default;

int BulletChain::dof() const { return impl_->tree.dof(); }

void BulletChain::step(const VecIn& tau) {
  Impl& s = *impl_;
  if (tau.size() != s.tree.dof()) throw std::invalid_argument("BulletChain::step: τ needs one value per joint");
  // Pitfall 3: torques are cleared after each step; apply them every step. Then exactly one step of dt.
  for (int i = 0; i < s.tree.dof(); ++i) {
    const int k = s.plan.link_of_tree_body[std::size_t(i)];
    s.body->addJointTorque(k, s.plan.links[std::size_t(k)].sign * tau[i]);
  }
  s.world->stepSimulation(s.dt, 0, s.dt);
}

void BulletChain::state(Eigen::VectorXd& q, Eigen::VectorXd& v) const {
  const Impl& s = *impl_;
  q.resize(s.tree.dof());
  v.resize(s.tree.dof());
  for (int i = 0; i < s.tree.dof(); ++i) {
    const int k = s.plan.link_of_tree_body[std::size_t(i)];
    const double sign = s.plan.links[std::size_t(k)].sign;
    q[i] = sign * s.body->getJointPos(k);
    v[i] = sign * s.body->getJointVel(k);
  }
}

Eigen::Vector2d BulletChain::pointPosition(int body, const Eigen::Vector2d& point) const {
  const Impl& s = *impl_;
  if (body < 0 || body >= s.tree.dof()) throw std::out_of_range("BulletChain::pointPosition: no such body");
  // Bullet's link frame sits at the body's centre of mass, turned as the body's frame.
  const btVector3 p = s.body->localPosToWorld(s.plan.link_of_tree_body[std::size_t(body)], bt(point - s.com[std::size_t(body)]));
  return {p.x(), p.y()};
}

std::string BulletChain::describe() const {
  return "Bullet 3.24 btMultiBody, " + std::to_string(impl_->tree.dof()) + " links, no colliders";
}

}  // namespace dyn::bullet
