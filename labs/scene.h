// Scene: what a lab wants drawn, as plain data in world coordinates (metres, z out of the
// plane for planar labs). Labs fill it from their state; render/ turns it into pixels.
// No GL here, so labs never depend on the renderer.
#pragma once
#include <algorithm>
#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

namespace dyn {

// RGBA in [0, 1]; alpha < 1 draws translucent (the Bullet ghost).
struct Color {
  float r = 0.8f, g = 0.8f, b = 0.8f, a = 1.0f;
};

// A rounded rod from p0 to p1 (links).
struct Capsule {
  Eigen::Vector3d p0, p1;
  double radius;
  Color color;
};

// A ball (joints, point masses).
struct Sphere {
  Eigen::Vector3d center;
  double radius;
  Color color;
};

// An oriented box (slider, rail, table); rotation maps box axes to world axes.
struct Box {
  Eigen::Vector3d center;
  Eigen::Vector3d half_extents;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Color color;
};

// A force arrow: from origin along vector (already scaled to metres by the lab).
struct Arrow {
  Eigen::Vector3d origin, vector;
  double radius;
  Color color;
};

// A polyline (trajectories, reference paths).
struct Polyline {
  std::vector<Eigen::Vector3d> points;
  double width_px = 2.0;
  Color color;
};

// The camera: looks from eye at target; orthographic when ortho, showing at least half_height
// metres above and below the target and, when half_width > 0, at least half_width either side:
// the frame's aspect decides which one binds, so one scene frames well at 4:3 and at 16:9.
struct Camera {
  Eigen::Vector3d eye{0, 0, 5}, target{0, 0, 0}, up{0, 1, 0};
  bool ortho = true;
  double half_height = 1.0;  // ortho: half the visible height in metres (at least)
  double half_width = 0.0;   // ortho: half the visible width in metres (at least); 0: no demand
  double fov_y_deg = 45.0;   // perspective only
  // Ortho: the half height actually shown in a frame of this aspect (width / height).
  double visibleHalfHeight(double aspect) const { return std::max(half_height, half_width / aspect); }
};

struct Scene {
  std::vector<Capsule> capsules;
  std::vector<Sphere> spheres;
  std::vector<Box> boxes;
  std::vector<Arrow> arrows;
  std::vector<Polyline> polylines;
  Camera camera;
  Color background{0.96f, 0.96f, 0.94f, 1.0f};
};

// A time series for the overlay's live plot.
struct Series {
  std::string name;
  std::vector<float> values;  // oldest first
  Color color;
};

// The overlay panel (Dear ImGui): a title, label/value lines and live plots.
struct Overlay {
  std::string title;
  std::vector<std::pair<std::string, std::string>> lines;
  std::vector<Series> plots;
};

}  // namespace dyn
