// Balls on Bullet links against static planes: the one contact model both builders share, for the
// rolling kind's Friction model (spatial_mechanism.cpp) and the plane_contact kind (planar and spatial).
// Private to physics/bullet/ (it speaks Bullet).
//
// Each ball is a btSphereShape on its link's own collider (a btCompoundShape of spheres when the ball is
// off the link's centre of mass or the link carries several), and each plane n·x = h a btStaticPlaneShape
// (solid on the −n side). Only a ball's link and its plane collide: one collision group per ball link
// and per plane, every other collider keeps mask 0 (shared/notes/bullet-reference.md, pitfall 1).
//   friction     the link collider's friction is μ, the plane's 1: Bullet multiplies the two (and clips
//                the product at 10: μ > 10 is refused); μ = 0 is frictionless. Two friction directions
//                (SOLVER_USE_2_FRICTION_DIRECTIONS, else Bullet keeps one) clipped together to the cone
//                |f_t| ≤ μ f_n; a friction force acts at the sphere's lowest point.
//   restitution  0 on both: a plastic touchdown.
//   touchdown    Bullet's contacts are speculative: a ball closer than the breaking threshold gets a row
//                that lets it reach the plane in the step and no further, so it lands exactly on the
//                plane (gap 0 to rounding, no bounce) and the impact impulse m v is spread over two
//                steps (the landing step takes m (v − δ/dt), δ the gap at its start; the next the rest):
//                the force read as impulse / dt spikes for two steps, then is exact (weight to 1e-12).
//                The threshold is by default relative to the shape (≈ 3.5 % of a sphere's radius: 35 µm
//                for 1 mm, less than one step of a falling ball), so a world with balls uses the absolute
//                gContactBreakingThreshold (2 cm) instead: without it a 1 mm ball dropped 5 cm sank
//                0.3–0.7 mm before Bullet saw the plane and popped back out at 0.1 m/s.
//   compliance   stiffness k > 0: the ball's collider gets setContactStiffnessAndDamping(k, d) and its
//                plane (BT_LARGE_FLOAT, 0), so the pair's series stiffness is k and damping d (Bullet adds
//                dampings: a plane's default 0.1 is overridden). Bullet's multibody solver turns them
//                into erp = dt k / (dt k + d), cfm = 1 / (dt (dt k + d)) on the normal row (λ ≥ 0): an
//                implicit-Euler spring-damper acting only while the ball is below the plane. It rests
//                at f_n = k · depth exactly (m g / k to 1e-14); moving, it is first order in dt and adds
//                a numerical damping ratio ≈ ω dt / 2 (ω = √(k/m)): an undamped bounce decays by
//                ≈ exp(−π ω dt) a period. A rigid plane gets no such flag (Baumgarte erp2 on
//                penetration, and none happens after a speculative touchdown).
//   radius       a ball of radius ρ < 1 mm is a 1 mm sphere about the same centre against the plane
//                moved by (1 mm − ρ) along −n: the gap n·c − ρ − h is the same, the normal force's line
//                through the centre is the same; only a friction force acts 1 mm − ρ lower (its moment
//                about c − ρ n is reported).
// One link carries balls against one plane with one μ, stiffness, damping and radius (a collider has one
// of each); more is refused (std::invalid_argument, "not yet").
#pragma once
#include <BulletDynamics/Featherstone/btMultiBodyConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>

#include <memory>
#include <string>
#include <vector>

#include "physics/bullet/bullet_world.h"

namespace dyn::bullet {

// One ball, in Bullet terms.
struct ContactBall {
  int link = -1;                   // Bullet link carrying it
  btVector3 centre{0, 0, 0};       // ball centre, Bullet link frame (its centre of mass, principal axes)
  double radius = 0;               // the description's ρ ≥ 0
  btVector3 normal{0, 0, 1};       // the plane's outward unit normal, world
  double height = 0;               // the plane n·x = height
  double mu = 0, stiffness = 0, damping = 0;
};

class ContactBalls {
 public:
  static constexpr double kMinRadius = 1e-3;  // m: smaller balls are this sphere (see the top)

  // Puts the balls on their links' colliders (colliders[k + 1] is link k's, as both builders keep them)
  // and adds the planes. `who` opens error messages.
  void build(BulletWorld& world, const std::vector<btMultiBodyLinkCollider*>& colliders, std::vector<ContactBall> balls,
             const std::string& who);
  // Removes the planes (before the world goes; the link colliders stay the builder's).
  void clear(BulletWorld& world);
  bool empty() const { return balls_.empty(); }

  // The plane's force on ball i over the last step (impulses / dt: normal and friction, world axes) and
  // its moment about the world point P. Zero when the ball did not touch.
  void force(const BulletWorld& world, int i, double dt, const btVector3& P, btVector3& f, btVector3& m) const;

 private:
  struct Placed {
    ContactBall ball;
    int child = -1;                                // compound child index (−1: the collider is this sphere)
    btMultiBodyLinkCollider* collider = nullptr;   // its link's
    btRigidBody* plane = nullptr;
  };
  std::vector<Placed> balls_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btRigidBody>> planes_;
};

// Pitfall 1: the base and each of `links` links of body get a collider on `shape` (constraints act only
// between links with one), with mask 0: no contacts (build() above gives a ball's link its group);
// added to the world and to colliders, the base's first.
void addLinkColliders(BulletWorld& world, btMultiBody& body, int links, btCollisionShape* shape,
                      std::vector<std::unique_ptr<btMultiBodyLinkCollider>>& colliders);

// A builder's teardown, before its world goes: its constraints, the balls' planes, its link colliders
// and its multibody taken out of the world, then freed.
void removeModel(BulletWorld& world, std::unique_ptr<btMultiBody>& body, std::vector<std::unique_ptr<btMultiBodyLinkCollider>>& colliders,
                 std::vector<std::unique_ptr<btMultiBodyConstraint>>& closures, ContactBalls& balls);

}  // namespace dyn::bullet
