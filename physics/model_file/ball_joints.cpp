// MuJoCo's ball and free joints onto the tree (chain.h: a ball is three tree bodies about the columns
// of R0, the body's xmat at qpos0, its quaternion stored once in q; a free joint is three slides along
// world x, y, z then a ball), so that q is MuJoCo's qpos and v its qvel, entry for entry:
//   ball   qpos (qw qx qy qz), relative rotation R0 R(Q) R0ᵀ in dynlab's world-aligned frames; qvel ω local
//   free   qpos (x y z qw qx qy qz): the body's origin and orientation R(Q) = (R(Q) R0ᵀ) R0; qvel the
//          origin's world velocity, then ω local
// A ball's springs (stiffness on the quaternion) and limits (a cone) are refused in one line.
#include <string>

#include "physics/model_file/mujoco_call.h"
#include "physics/model_file/model_file.h"
#include "physics/model_file/number_text.h"

namespace dyn::model_file::detail {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;

void checkBallJoint(const std::string& path, const mjModel* m, int j, const std::string& name, const std::string& body) {
  const bool free = m->jnt_type[j] == mjJNT_FREE;
  const std::string where = path + ": joint '" + name + "' (body '" + body + "') is a " + (free ? "free" : "ball") + " joint";
  if (m->jnt_stiffness[j] != 0 && !(m->opt.disableflags & mjDSBL_PASSIVE))
    throw ModelFileError(where + " with stiffness " + detail::numberText(m->jnt_stiffness[j], 6) +
                         "; dynlab holds springs on hinge and slide joints only (leave its stiffness 0)");
  if (!free && m->jnt_limited[j] && !(m->opt.disableflags & mjDSBL_LIMIT))
    throw ModelFileError(where + " with a range (a cone); dynlab holds limits on hinge and slide joints only (leave the ball joint unlimited)");
}

void addBallJoint(const mjModel* m, const mjData* d, int b, int j, const std::string& name, const std::string& body, int& link, Vec3& origin,
                  LoadedModel& out) {
  MechanismModel<Spatial>& mech = out.mechanism;
  const bool free = m->jnt_type[j] == mjJNT_FREE;
  const int qadr = m->jnt_qposadr[j];
  auto entry = [&](const char* suffix, int qpos) {
    Joint jt;
    jt.name = name + suffix;
    jt.body = body;
    jt.type = free ? "free" : "ball";
    jt.qpos = qpos;
    out.joints.push_back(jt);
  };
  // A free joint's origin is the body's; three slides carry it there from the world's origin (their
  // placements undo the travel at qpos0, as model_file.cpp's slides do).
  const Vec3 o = free ? Vec3(d->xpos + 3 * b) : Vec3(d->xanchor + 3 * j);
  if (free) {
    static const char* const kAxis[3] = {"_x", "_y", "_z"};
    for (int k = 0; k < 3; ++k) {
      const Vec3 a = Vec3::Unit(k);
      Spatial::Transform X{Mat3::Identity(), (k == 0 ? Vec3(o - origin) : Vec3(Vec3::Zero())) - a * m->qpos0[qadr + k], true};
      link = mech.tree.addBody(link, JointType::Prismatic, a, X, Spatial::Mat::Zero());
      entry(kAxis[k], qadr + k);
      out.coordinates.push_back(name + kAxis[k]);
    }
    origin = o;
  }
  // The ball about the anchor: R0 the body's orientation at qpos0 (where a ball's Q is 1; a free
  // joint's Q0 gives it: pre = R0 R(Q0)ᵀ = 1).
  const Mat3 R0 = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d->xmat + 9 * b);
  const int qball = qadr + (free ? 3 : 0);
  const Mat3 pre = free ? Mat3::Identity() : R0;
  link = mech.tree.addBall(link, Spatial::Transform{Mat3::Identity(), o - origin, false}, pre, R0, Spatial::Mat::Zero());
  origin = o;
  for (const char* s : {"_wx", "_wy", "_wz"}) entry(s, qball);
  for (const char* s : {"_qw", "_qx", "_qy", "_qz"}) out.coordinates.push_back(name + s);
}

}  // namespace dyn::model_file::detail
