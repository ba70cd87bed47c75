// Framing: where a scene goes in a frame (no GL). The renderer uses it when a scene asks to be
// fitted (Scene::framing): the scene's box goes into the largest rectangle the overlay panel
// leaves free, as large as it fits, centred there. Pure functions, so tests check layouts
// without drawing.
#pragma once
#include <Eigen/Geometry>
#include <vector>

#include "labs/scene.h"

namespace dyn {

// A rectangle of pixels: x right, y down from the frame's top-left corner.
struct PixelRect {
  double x = 0, y = 0, w = 0, h = 0;
  bool empty() const { return !(w > 0 && h > 0); }
  double right() const { return x + w; }
  double bottom() const { return y + h; }
  // True when the two overlap by more than a touching edge.
  bool intersects(const PixelRect& o) const {
    return !empty() && !o.empty() && x < o.right() && o.x < right() && y < o.bottom() && o.y < bottom();
  }
};

// The box every primitive of the scene occupies (radii, arrow heads, polylines, planes, cones and
// springs included); empty for an empty scene.
Eigen::AlignedBox3d sceneBounds(const Scene& scene);

// Where `box` lands on screen under `camera` in a width x height frame: the pixel box of its
// eight corners (exact for ortho, and for perspective as long as the box is in front of the eye).
PixelRect projectedBox(const Camera& camera, int width, int height, const Eigen::AlignedBox3d& box);
// The pixel box of the points (the same for a box's eight corners).
PixelRect projectedPoints(const Camera& camera, int width, int height, const std::vector<Eigen::Vector3d>& points);

// The free part of a width x height frame with `panel` (a rectangle touching the top-left corner;
// empty: no panel) in it: the whole frame, or the part right of the panel, or the part below
// it, whichever shows `box` (seen as `camera` looks) the larger. A gap of `gap` pixels is kept
// from the panel.
PixelRect freeRect(int width, int height, const PixelRect& panel, const Camera& camera,
                   const Eigen::AlignedBox3d& box, double gap);
// The same for what the points show (Framing::points), the box's version being its eight corners'.
PixelRect freeRect(int width, int height, const PixelRect& panel, const Camera& camera,
                   const std::vector<Eigen::Vector3d>& points, double gap);

// `camera` moved (target, eye, and the ortho half sizes or the perspective distance) so that `box`
// fills `free` as far as its aspect allows, centred in it, with `margin` spare (1.08: 4 % on each
// side); the view direction, up, projection and fov are kept. An empty box leaves it unchanged.
Camera fitCamera(Camera camera, const Eigen::AlignedBox3d& box, int width, int height, const PixelRect& free,
                 double margin);
// The same fit for the points' picture (their box's centre the starting target); fitCamera(box) is
// this for the box's eight corners.
Camera fitCamera(Camera camera, const std::vector<Eigen::Vector3d>& points, int width, int height, const PixelRect& free,
                 double margin);

// Where an inset goes (labs/scene.h Inset): its rectangle in `free` (the part of the frame the main
// scene was fitted into), whole pixels, border included.
PixelRect insetRect(const PixelRect& free, const Inset& inset);

}  // namespace dyn
