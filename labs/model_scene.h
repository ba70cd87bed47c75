// A loaded model (physics/model_file) as a picture: its geoms (model_file::Drawing) placed at any state
// q by the description's own kinematics, its joints and loop closures marked, a second state (the
// Bullet run) as a translucent ghost, framed like every lab (Scene::framing): a planar mechanism
// side-on and orthographic, looking along its hinges' common axis; a spatial one in perspective; up
// against gravity; a spatial one that draws shapes of its own fitted to those shapes' points, not to
// their box, so the robot fills the frame. And the overlay panel of a run's trace (time, energy,
// closure residual).
#pragma once
#include <Eigen/Geometry>
#include <vector>

#include "labs/scene.h"
#include "labs/trace.h"
#include "physics/chain.h"
#include "physics/model_file/model_file.h"

namespace dyn {

class ModelPicture {
 public:
  // Keeps a reference to model: it must outlive the picture.
  explicit ModelPicture(const model_file::LoadedModel& model);

  // World positions at q of each tree body's joint anchor (one per coordinate).
  std::vector<Eigen::Vector3d> anchors(const VecN& q) const;
  // The box what is drawn at q occupies (floors left out).
  Eigen::AlignedBox3d bounds(const VecN& q) const;
  // The scene at q; ghost, when given, drawn translucent behind it; framed around `frame` (empty:
  // bounds(q)), so a run framed around the space it moves through holds its camera still, and, when
  // `points` are given (runPoints), fitted to their picture (Scene::framing.points).
  void scene(const VecN& q, const VecN* ghost, const Eigen::AlignedBox3d& frame, Scene& out,
             const std::vector<Eigen::Vector3d>& points = {}) const;
  // Points whose picture holds what is drawn at q (model_points.cpp): each mesh's vertices that are
  // farthest along 98 directions, the corners of a polytope round each ball (capsule ends, joints),
  // cylinder and bone, a box's corners; floors left out. Appended to out.
  void shapePoints(const VecN& q, std::vector<Eigen::Vector3d>& out) const;
  // A stage under a spatial model that stands on the world and draws no floor of its own: a floor slab
  // with a grid, the framed box's footprint a twentieth of its size below it, and a pedestal from it up
  // to each joint on the world, so the base does not float; the framed box grows to hold them. Call
  // after scene(). Nothing for a planar model (its ground mounts show where it is fixed) or one with a
  // floor of its own. A scene fitted to points gets the pedestal's among them, not the floor's.
  void stage(Scene& out) const;
  // A floating base (the first free joint's body): the camera follows it, its frames framed by the space
  // the robot moves through about the base (runBounds, runPoints) placed at the base's position at each
  // row, so a robot that falls or walks stays framed rather than a speck in the box of its whole path.
  bool follows() const { return base_qpos_ >= 0; }
  // The floating base's position at q (a free joint's x y z), else 0.
  Eigen::Vector3d base(const VecN& q) const;
  // True when every hinge turns about one axis and every slide moves across it: drawn side-on.
  bool planar() const { return planar_; }
  // True when its frames are fitted to shapePoints: a spatial model drawing geoms of its own (a
  // planar one is seen side-on, where its box is already its outline; bones alone keep the box).
  bool fitsPoints() const { return !planar_ && !local_points_.empty(); }

 private:
  void place(const VecN& q) const;  // the tree's world frames at q
  Eigen::Vector3d point(int link, const Eigen::Vector3d& p) const;
  Eigen::Matrix3d rotation(int link) const;
  void drawBodies(bool ghost, Scene& out) const;
  bool groundPivot(std::size_t link) const;  // a hinge on the world: drawn on a mount
  bool marked(std::size_t link) const;       // its joint drawn as a ball: not a free joint's slide carrier
  void keepShapePoints();                     // local_points_, once (model_points.cpp)

  const model_file::LoadedModel& model_;
  mutable TreeData<Spatial> data_;
  bool planar_ = false;
  Eigen::Vector3d axis_ = Eigen::Vector3d::UnitY(), up_ = Eigen::Vector3d::UnitZ();
  double joint_radius_ = 0.01, rod_radius_ = 0.005;
  int base_qpos_ = -1;  // the followed free joint's x in q, or −1
  // Per drawn geom (floors aside) its link and the points shapePoints places, in the link's frame.
  std::vector<std::pair<int, std::vector<Eigen::Vector3d>>> local_points_;
};

// The coordinates q (or rates v) of a model run's trace row: columns 1..n (n..2n), as app/cli/model/model.cpp writes them.
VecN traceQ(const Trace& trace, std::size_t row, int n);

// The space a run moves through: the box of what is drawn over its rows (and the ghost's), so the
// camera holds still from frame to frame, as in every lab; for a picture that follows its floating
// base, about the base (scene() places it there).
Eigen::AlignedBox3d runBounds(const ModelPicture& picture, int n, const Trace& trace, const Trace* ghost);
// The same space as points (shapePoints over the rows runBounds takes, thinned to those farthest along
// 218 directions), for ModelPicture::scene; none unless the picture fitsPoints().
std::vector<Eigen::Vector3d> runPoints(const ModelPicture& picture, int n, const Trace& trace, const Trace* ghost);

// The overlay panel at a row: time, energy and its balance, closure residual (and the ghost's), and
// live plots of the energy balance and the residual over the last two seconds.
void modelOverlay(const std::string& title, const std::string& engines, const Trace& trace, std::size_t row, double dt, const Trace* ghost, Overlay& out);

}  // namespace dyn
