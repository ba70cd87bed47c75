// Rounding residues made exact (Spatial::kResidue = 1e-12): MuJoCo's numbers at qpos0 carry the
// rounding of its frames' quarter turns (cos π/2 = 6e-17), and Spatial::central's round trip
// I_c → I_O → I_c leaves products of a few ε. The loader makes a joint axis' residue components and a
// central inertia's residue products exact zeros, and central() its own round trip's; what a file
// states (an axis tilted by 1e-6, a product of 1e-6 of the inertia) stays. The PUMA 560's joints 2, 3
// and 5 then turn about −e_y exactly and every link's central inertia is diagonal, with M and h still
// MuJoCo's (model_file_test holds every file to mj_fullM and qfrc_bias).
#include <doctest/doctest.h>

#include "physics/model_file/model_file.h"
#include "tests/physics/model_file/fixtures.h"

using namespace dyn;
using namespace dyn::test_model_file;

namespace {

// Largest |product of inertia| of a central inertia.
double largestProduct(const Eigen::Matrix3d& Ic) {
  double p = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (i != j) p = std::max(p, std::abs(Ic(i, j)));
  return p;
}

}  // namespace

TEST_CASE("the loader snaps an axis' and an inertia's rounding residues to exact zeros, and leaves a stated tilt") {
  static const std::filesystem::path dir = scratchFolder("residues");
  // Body a: about (0, −1, 2.2e-16), as MuJoCo reads a quarter turn's −e_y, its principal frame turned
  // a quarter turn about x (products of 1e-17). Body b: about an axis tilted by 1e-6 from −e_y, with a
  // principal frame tilted by 1e-3 (a product of inertia ~3e-6 of its moments). Body c: the exact
  // axis −e_z, a diagonal inertia off its centre in three coordinates (central()'s round trip).
  const auto file = writeFile(dir, "residues.xml", R"(<mujoco>
  <worldbody>
    <body name="a">
      <joint name="ja" type="hinge" axis="0 -1 2.220446049250313e-16"/>
      <inertial pos="0.1 0.2 0.3" mass="1" diaginertia="0.1 0.2 0.3" quat="0.7071067811865476 0.7071067811865476 0 0"/>
      <body name="b" pos="0.3 0 0">
        <joint name="jb" type="hinge" axis="0 -1 1e-6"/>
        <inertial pos="0.1 0.2 0.3" mass="1" diaginertia="0.1 0.2 0.3" quat="0.9999998750000026 0.0005 0 0"/>
        <body name="c" pos="0.3 0 0">
          <joint name="jc" type="hinge" axis="0 0 -1"/>
          <inertial pos="0.17 -0.23 0.29" mass="2.3" diaginertia="0.1 0.2 0.3"/>
  </body></body></body></worldbody>
</mujoco>)");
  const model_file::LoadedModel m = model_file::load(file.string());
  const auto& bodies = m.mechanism.tree.bodies;
  REQUIRE(bodies.size() == 3);
  // a: exactly −e_y on the coordinate-axis path, its central inertia exactly diagonal.
  CHECK(bodies[0].axis == -Spatial::Axis::UnitY());
  CHECK(bodies[0].coordinate_axis == 1);
  CHECK(bodies[0].coordinate_sign == -1);
  CHECK(bodies[0].central.diagonal);
  CHECK(largestProduct(bodies[0].central.Ic) == 0.0);
  // b: the tilt stays (z = 1e-6, to rounding), off the coordinate-axis path; so does the product.
  CHECK(std::abs(bodies[1].axis.z() - 1e-6) < 1e-15);
  CHECK(bodies[1].coordinate_axis == -1);
  CHECK(!bodies[1].central.diagonal);
  CHECK(largestProduct(bodies[1].central.Ic) > 1e-5);
  // c: −e_z, and the round trip's residues of a centre off three axes are zeros.
  CHECK(bodies[2].coordinate_axis == 2);
  CHECK(bodies[2].coordinate_sign == -1);
  CHECK(bodies[2].central.diagonal);
  CHECK(std::abs(bodies[2].central.Ic(2, 2) - 0.3) < 1e-15);
}

TEST_CASE("the PUMA 560 file: joints 2, 3 and 5 about -e_y exactly, every link's central inertia diagonal") {
  const model_file::LoadedModel m = model_file::load(model("puma560.urdf"));
  const auto& bodies = m.mechanism.tree.bodies;
  REQUIRE(bodies.size() == 6);
  const int axis[6] = {2, 1, 1, 2, 1, 2}, sign[6] = {1, -1, -1, 1, -1, 1};
  for (int i = 0; i < 6; ++i) {
    CAPTURE(i);
    CHECK(bodies[std::size_t(i)].coordinate_axis == axis[i]);
    CHECK(bodies[std::size_t(i)].coordinate_sign == sign[i]);
    CHECK(bodies[std::size_t(i)].central.diagonal);
  }
}

TEST_CASE("Spatial::central: its round trip's residues are zeros, a stated product stays") {
  // A diagonal I_c about a centre off all three axes: I_O's products are m c_i c_j, and subtracting
  // them back leaves ε-sized residues unless they are snapped.
  const Eigen::Matrix3d diag = Eigen::Vector3d(0.13, 0.539, 0.524).asDiagonal();
  const Spatial::Central C = Spatial::central(Spatial::inertia(17.4, {0.068, -0.2275, 0.006}, diag));
  CHECK(C.diagonal);
  CHECK(largestProduct(C.Ic) == 0.0);
  CHECK((C.Ic - diag).norm() < 1e-15);
  // A product of 1e-9 (1e-9 of tr I_O, 1000× the threshold) is the body's: kept.
  Eigen::Matrix3d tilted = diag;
  tilted(0, 1) = tilted(1, 0) = 1e-9;
  const Spatial::Central T = Spatial::central(Spatial::inertia(17.4, {0.068, -0.2275, 0.006}, tilted));
  CHECK(!T.diagonal);
  CHECK(std::abs(T.Ic(0, 1) - 1e-9) < 1e-15);
}
