// Shared test arms: the planar 3-link arm and a spatial 3-DOF arm (the pen-on-table kind).
#pragma once
#include "physics/chain.h"

namespace dyn::test {

inline TreeModel<Planar> planarArm() {
  TreeModel<Planar> m;
  const double L[3] = {0.3, 0.6, 0.2}, mass[3] = {1.0, 1.5, 0.5};
  for (int i = 0; i < 3; ++i) {
    const Planar::Pos off = i == 0 ? Planar::Pos::Zero() : Planar::Pos(L[i - 1], 0.0);
    m.addBody(i - 1, JointType::Revolute, Planar::Axis::Zero(), Planar::translation(off),
              Planar::inertia(mass[i], Planar::Pos(L[i] / 2, 0.02 * (i + 1)), mass[i] * L[i] * L[i] / 12));
  }
  m.gravity << 0, 0, -9.81;
  return m;
}

// Base yaw about z, shoulder and elbow about y; offset centres of mass and full inertias.
inline TreeModel<Spatial> spatialArm() {
  TreeModel<Spatial> m;
  Eigen::Matrix3d I0 = Eigen::Vector3d(0.02, 0.02, 0.01).asDiagonal();
  Eigen::Matrix3d I1;
  I1 << 0.01, 0.001, 0, 0.001, 0.03, 0.002, 0, 0.002, 0.03;
  Eigen::Matrix3d I2 = Eigen::Vector3d(0.005, 0.02, 0.02).asDiagonal();
  m.addBody(-1, JointType::Revolute, {0, 0, 1}, Spatial::translation({0, 0, 0.1}),
            Spatial::inertia(2.0, {0.01, 0, 0.1}, I0));
  m.addBody(0, JointType::Revolute, {0, 1, 0}, Spatial::translation({0, 0, 0.2}),
            Spatial::inertia(1.5, {0.2, 0.01, 0}, I1));
  m.addBody(1, JointType::Revolute, {0, 1, 0}, Spatial::translation({0.4, 0, 0}),
            Spatial::inertia(0.8, {0.15, 0, 0.01}, I2));
  m.gravity << 0, 0, 0, 0, 0, -9.81;
  return m;
}

}  // namespace dyn::test
