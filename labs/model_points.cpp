// The points a model picture is framed by (model_scene.h ModelPicture::shapePoints, runPoints): what
// its shapes reach, so a spatial robot's frames are fitted to its outline rather than to the box
// round it, which seen at an angle is much larger than the robot.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "labs/model_scene.h"
#include "labs/run_bounds.h"
#include "physics/det/det.h"

namespace dyn {
namespace {

using Vec3 = Eigen::Vector3d;
using Points = std::vector<Vec3>;
using Shape = model_file::Geom::Shape;

// The unit directions to the surface points of the cube [-k, k]^3's integer grid: 26 for k = 1, 98
// for k = 2, 218 for k = 3; the larger k, the closer every direction is to one of them.
Points directions(int k) {
  Points out;
  for (int x = -k; x <= k; ++x)
    for (int y = -k; y <= k; ++y)
      for (int z = -k; z <= k; ++z)
        if (std::max({std::abs(x), std::abs(y), std::abs(z)}) == k) out.push_back(Vec3(x, y, z).normalized());
  return out;
}

// The points farthest from `centre` along each of `dirs`, as points are added (each kept once).
class Farthest {
 public:
  Farthest(const Points& dirs, const Vec3& centre) : dirs_(dirs), centre_(centre), best_(dirs.size(), -1e300), at_(dirs.size()) {}
  void add(const Vec3& p) {
    for (std::size_t k = 0; k < dirs_.size(); ++k) {
      const double h = (p - centre_).dot(dirs_[k]);
      if (h > best_[k]) best_[k] = h, at_[k] = p;
    }
  }
  Points points() const {
    Points out;
    for (std::size_t k = 0; k < dirs_.size(); ++k)
      if (best_[k] > -1e300 && std::find(out.begin(), out.end(), at_[k]) == out.end()) out.push_back(at_[k]);
    return out;
  }

 private:
  const Points& dirs_;
  Vec3 centre_;
  std::vector<double> best_;
  Points at_;
};

// A ball of radius r round c: 26 points whose hull holds it (every direction is within 27.5° of one of
// the 26, and cos 27.5° > 1 / 1.13: the points at 1.13 r reach past the ball's edge everywhere).
void ball(const Vec3& c, double r, Points& out) {
  static const Points dirs = directions(1);
  for (const Vec3& d : dirs) out.push_back(c + 1.13 * r * d);
}

// A disc's rim of radius r round c across axes x, y: 16 points whose polygon holds the circle.
void rim(const Vec3& c, const Vec3& x, const Vec3& y, double r, Points& out) {
  for (int k = 0; k < 16; ++k) {
    const double a = 2 * std::numbers::pi * k / 16;
    out.push_back(c + r / det::cos(std::numbers::pi / 16) * (det::cos(a) * x + det::sin(a) * y));
  }
}

// A geom's points in its link's frame.
Points geomPoints(const model_file::Geom& g) {
  Points out;
  const Vec3 z = g.rot.col(2);
  switch (g.shape) {
    case Shape::Sphere: ball(g.pos, g.size[0], out); break;
    case Shape::Capsule:
      ball(g.pos - g.size[1] * z, g.size[0], out);
      ball(g.pos + g.size[1] * z, g.size[0], out);
      break;
    case Shape::Cylinder:
      for (const double s : {-1.0, 1.0}) rim(g.pos + s * g.size[1] * z, g.rot.col(0), g.rot.col(1), g.size[0], out);
      break;
    case Shape::Box:
      for (int k = 0; k < 8; ++k)
        out.push_back(g.pos + g.rot * Vec3((k & 1 ? 1 : -1) * g.size[0], (k & 2 ? 1 : -1) * g.size[1], (k & 4 ? 1 : -1) * g.size[2]));
      break;
    case Shape::Mesh: {
      // Its vertices farthest from its box's centre along 218 directions (every direction within
      // 12.6° of one of them: the hull of these misses the mesh's outline by a few per cent of its size).
      static const Points dirs = directions(3);
      Farthest far(dirs, g.mesh->box.center());
      for (const Eigen::Vector3f& v : g.mesh->vertices) far.add(v.cast<double>());
      for (const Vec3& v : far.points()) out.push_back(g.pos + g.rot * v);
      break;
    }
    case Shape::Plane: break;
  }
  return out;
}

}  // namespace

void ModelPicture::keepShapePoints() {
  local_points_.clear();
  for (const auto& g : model_.drawing.geoms)
    if (g.shape != Shape::Plane) local_points_.emplace_back(g.link, geomPoints(g));
}

void ModelPicture::shapePoints(const VecN& q, std::vector<Vec3>& out) const {
  place(q);
  for (const auto& [link, points] : local_points_)
    for (const Vec3& p : points) out.push_back(point(link, p));
  for (const auto& b : model_.drawing.bones) ball(point(b.link, b.from), rod_radius_, out), ball(point(b.link, b.to), rod_radius_, out);
  for (std::size_t i = 0; i < data_.X_world.size(); ++i)
    if (marked(i)) ball(data_.X_world[i].r, joint_radius_, out);
}

std::vector<Vec3> runPoints(const ModelPicture& picture, int n, const Trace& trace, const Trace* ghost) {
  if (!picture.fitsPoints() || trace.rows() == 0) return {};
  // The farthest points from the start's centre along 218 directions, over the rows runBounds takes:
  // the fit may miss the outline by a few per cent of the robot's size, inside the frame's margin.
  static const Points dirs = directions(3);
  // A picture that follows its floating base: the points about the base (ModelPicture::follows).
  Points row;
  const VecN q0 = traceQ(trace, 0, n);
  picture.shapePoints(q0, row);
  Eigen::AlignedBox3d start;
  for (const Vec3& p : row) start.extend(picture.follows() ? Vec3(p - picture.base(q0)) : p);
  Farthest far(dirs, start.center());
  forBoundsRows(trace, ghost, [&](const Trace& run, std::size_t r) {
    row.clear();
    const VecN q = traceQ(run, r, n);
    picture.shapePoints(q, row);
    for (const Vec3& p : row) far.add(picture.follows() ? Vec3(p - picture.base(q)) : p);
  });
  return far.points();
}

}  // namespace dyn
