// MuJoCo 3 syntax through the real binary (issue 40 item 7): a two-link loop written with a
// site-to-site <connect> loads and runs on `model` and `bench`, the translation noted; an attribute of a
// later MuJoCo in an included file is refused on each command in one line naming the included file, its
// line, the element and the attribute, exit 2, nothing written.
#include <doctest/doctest.h>

#include <algorithm>

#include "tests/app/cli_run.h"

using namespace dyn::test::cli;

namespace {

// A pendulum pair tied at the tips by sites (a closed chain of two links hanging from two pivots).
const char* kLoop = R"(<mujoco model="tied">
  <option timestep="0.002"/>
  <default><geom type="capsule" size="0.01" contype="0" conaffinity="0"/></default>
  <worldbody>
    <body name="a" quat="0.707107 -0.707107 0 0">
      <joint name="ja" type="hinge" axis="0 0 1"/>
      <geom fromto="0 0 0 0.1 -0.2 0" mass="0.3"/>
      <body name="a2" pos="0.1 -0.2 0">
        <joint name="ja2" type="hinge" axis="0 0 1"/>
        <geom fromto="0 0 0 0.1 0 0" mass="0.1"/>
        <site name="tip_a" pos="0.1 0 0"/>
      </body>
    </body>
    <body name="b" pos="0.3 0 0" quat="0.707107 -0.707107 0 0">
      <joint name="jb" type="hinge" axis="0 0 1" range="-3 3"/>
      <geom fromto="0 0 0 -0.1 -0.2 0" mass="0.3"/>
      <site name="tip_b" pos="-0.1 -0.2 0"/>
    </body>
  </worldbody>
  <equality><connect site1="tip_a" site2="tip_b"/></equality>
</mujoco>
)";

}  // namespace

TEST_CASE("a MuJoCo 3 site-to-site loop runs on model and bench") {
  TempDir dir("mjcf3_loop");
  writeFile(dir / "tied.xml", kLoop);
  const Result m = dynlab(dir, {"model", "tied.xml", "--duration", "0.2", "--engine", "hand", "--out", "o"});
  INFO(m.err);
  CHECK(m.code == 0);
  CHECK(m.out.find("MuJoCo 3 syntax translated for Debian's MuJoCo 2.2.2") != std::string::npos);
  CHECK(m.out.find("1 closure") != std::string::npos);
  const Result b = dynlab(dir, {"bench", "tied.xml", "--steps", "100"});
  INFO(b.err);
  CHECK(b.code == 0);
}

TEST_CASE("a later MuJoCo's attribute in an included file: one line naming it, exit 2, on every command") {
  TempDir dir("mjcf3_later");
  fs::create_directories(dir / "parts");
  writeFile(dir / "arm.xml", R"(<mujoco>
  <worldbody>
    <include file="parts/arm_body.xml"/>
  </worldbody>
</mujoco>
)");
  writeFile(dir / "parts" / "arm_body.xml", R"(<mujoco>
  <body name="arm">
    <joint name="shoulder" type="hinge" axis="0 1 0" actuatorfrcrange="-5 5"/>
    <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.01" mass="1" contype="0" conaffinity="0"/>
  </body>
</mujoco>
)");
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"model", "arm.xml", "--out", "o"}, {"run", "arm.xml", "--out", "o"}, {"bench", "arm.xml"}}) {
    CAPTURE(shown(args));
    const Result r = dynlab(dir, args);
    CHECK(r.code == 2);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK(r.err.find("arm.xml: included 'parts/arm_body.xml': line 3: attribute 'actuatorfrcrange' of <joint> is MuJoCo 3.x syntax "
                     "that Debian's MuJoCo 2.2.2 does not read") != std::string::npos);
    CHECK(!fs::exists(dir / "o"));
  }
}
