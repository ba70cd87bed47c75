// MuJoCo 3 syntax read by Debian's MuJoCo 2.2.2 (physics/model_file/mjcf3.cpp): a planar five-bar
// written as onshape-to-robot writes one (body frames turned so each hinge is its local z, a default
// class with frictionloss and armature, sites closing the loop, <connect site1 site2>, position servos
// with kp and dampratio from the class, kv on one, inheritrange on the other) is the same mechanism as the file written in
// 2.2.2's terms (body1/anchor, <general> servos): the compiled models agree, the loop closes at the
// reference pose and over a 1 s run to 1e-12, and the motion is the same. An include is translated too;
// a loop open at the reference pose and an attribute of a later MuJoCo are refused in one line.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "physics/constrained_mechanism.h"
#include "physics/integrate.h"
#include "physics/model_file/mujoco_call.h"
#include "tests/physics/model_file/fixtures.h"

using namespace dyn;
namespace fs = std::filesystem;
using test_model_file::errorOf;
using test_model_file::maxAbs;
using test_model_file::writeFile;

namespace {

const fs::path& folder() {
  static const fs::path d = test_model_file::scratchFolder("mjcf3");
  return d;
}

// The five-bar's bodies: cranks on ground pivots A = (0, 0, 0) and E = (0.3, 0, 0), links meeting at
// C = (0.15, 0, 0.4), in the vertical x-z plane; each body's frame turned −90° about x (its z is the
// world's y, the hinges' axis), so a world point (x, 0, z) is (x, −z, 0) in it. `site1`/`site2` close
// the loop at C (written by the caller: sites, or nothing).
std::string bodies(const std::string& site1, const std::string& site2) {
  return R"(
  <worldbody>
    <body name="base" childclass="fivebar">
      <inertial pos="0.15 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>
      <body name="left_crank" pos="0 0 0" quat="0.707107 -0.707107 0 0">
        <joint name="left_motor" type="hinge" limited="true" range="-1 2"/>
        <inertial pos="-0.025 -0.1 0" mass="0.15" fullinertia="0.0005 0.00005 0.0005 0.0001 0 0"/>
        <body name="left_link" pos="-0.05 -0.2 0" quat="1 0 0 0">
          <joint name="left_passive" type="hinge"/>
          <inertial pos="0.1 -0.1 0" mass="0.2" fullinertia="0.0007 0.0007 0.0013 0.0006 0 0"/>
          )" + site1 + R"(
        </body>
      </body>
      <body name="right_crank" pos="0.3 0 0" quat="0.707107 -0.707107 0 0">
        <joint name="right_motor" type="hinge"/>
        <inertial pos="0.025 -0.1 0" mass="0.15" fullinertia="0.0005 0.00005 0.0005 -0.0001 0 0"/>
        <body name="right_link" pos="0.05 -0.2 0">
          <joint name="right_passive" type="hinge"/>
          <inertial pos="-0.1 -0.1 0" mass="0.2" fullinertia="0.0007 0.0007 0.0013 -0.0006 0 0"/>
          )" + site2 + R"(
        </body>
      </body>
    </body>
  </worldbody>)";
}

// MuJoCo 3, as onshape-to-robot writes it: the servos' damping from the class's dampratio (one with kv;
// the other's ctrlrange from its joint's range by inheritrange),
// the loop closed by sites (site2 turned, its position from a class of its own).
std::string mujoco3(const std::string& site2_pos = "-0.2 -0.2 0") {
  return R"(<?xml version="1.0" ?>
<!-- Generated the way onshape-to-robot writes a robot -->
<mujoco model="fivebar3">
  <compiler angle="radian" autolimits="true"/>
  <option noslip_iterations="1" integrator="implicitfast"></option>
  <default>
    <default class="fivebar">
      <joint frictionloss="0.1" armature="0.005"/>
      <position kp="50" dampratio="1"/>
      <default class="closing">
        <site group="3" pos=")" + site2_pos + R"("/>
      </default>
    </default>
  </default>)" +
         bodies(R"(<site group="3" name="closing_C_1" pos="0.2 -0.2 0" quat="1 0 0 0"/>)",
                R"(<site class="closing" name="closing_C_2" quat="0 0 0 1"/>)") + R"(
  <actuator>
    <position class="fivebar" name="left_motor" joint="left_motor" inheritrange="0.5"/>
    <position class="fivebar" name="right_motor" joint="right_motor" kv="2" forcerange="-10 10" ctrlrange="-3.14 3.14"/>
  </actuator>
  <equality>
    <connect site1="closing_C_1" site2="closing_C_2"/>
  </equality>
</mujoco>
)";
}

std::string exact(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}

// The same mechanism in MuJoCo 2.2.2's terms: body1/body2/anchor, <general> servos with kv written out.
std::string mujoco2(double kv_left) {
  return R"(<mujoco model="fivebar2">
  <compiler angle="radian"/>
  <option noslip_iterations="1" integrator="implicit"/>
  <default>
    <default class="fivebar">
      <joint frictionloss="0.1" armature="0.005"/>
    </default>
  </default>)" +
         bodies("", "") + R"(
  <actuator>
    <general name="left_motor" joint="left_motor" ctrllimited="true" ctrlrange="-0.25 1.25" gaintype="fixed" biastype="affine"
             gainprm="50" biasprm="0 -50 )" + exact(-kv_left) + R"("/>
    <general name="right_motor" joint="right_motor" ctrllimited="true" ctrlrange="-3.14 3.14" forcelimited="true" forcerange="-10 10"
             gaintype="fixed" biastype="affine" gainprm="50" biasprm="0 -50 -2"/>
  </actuator>
  <equality>
    <connect body1="left_link" body2="right_link" anchor="0.2 -0.2 0"/>
  </equality>
</mujoco>
)";
}

// (q, v) after each step of a 1 s passive run from q0 at rest (RK4 + projection at 1 ms), stacked.
std::vector<VecN> passiveRun(ConstrainedMechanism<Spatial>& m, VecN q) {
  StepOptions o;
  o.dt = 1e-3;
  VecN v = VecN::Zero(q.size());
  std::vector<VecN> out;
  while (out.size() < 1000) {
    REQUIRE(step(m, o, VecN::Zero(q.size()), q, v));
    VecN x(2 * q.size());
    x << q, v;
    out.push_back(x);
  }
  return out;
}

std::shared_ptr<const model_file::detail::Compiled> compiled(const fs::path& file) { return model_file::detail::compile(file.string(), nullptr); }

// The file without its actuators (dynlab runs model files passive; servos are another item's).
std::string passive(std::string text) {
  const std::size_t a = text.find("  <actuator>"), b = text.find("</actuator>");
  return text.erase(a, b + std::string("</actuator>\n").size() - a);
}

}  // namespace

TEST_CASE("an onshape-style MuJoCo 3 five-bar compiles as the same file written for MuJoCo 2.2.2") {
  const auto m3 = compiled(writeFile(folder(), "fivebar3.xml", mujoco3()));
  const mjModel* m = m3->m;
  REQUIRE(m->nu == 2);
  REQUIRE(m->neq == 1);
  // dampratio 1 on the left servo: kv = 2 √(kp M_jj) with M_jj the crank joint's inertia at qpos0,
  // armature included (MuJoCo 3's rule), from the 2.2.2 model's own diagonal.
  const double kv_left = 2 * std::sqrt(50 * m->dof_M0[0]);
  MESSAGE("left servo: kv " << kv_left << " from dampratio 1");
  const auto m2 = compiled(writeFile(folder(), "fivebar2.xml", mujoco2(kv_left)));
  const mjModel* r = m2->m;
  for (int a = 0; a < 2; ++a) {
    CAPTURE(a);
    CHECK(m->actuator_gaintype[a] == mjGAIN_FIXED);
    CHECK(m->actuator_biastype[a] == mjBIAS_AFFINE);
    CHECK(m->actuator_trnid[2 * a] == r->actuator_trnid[2 * a]);
    for (int k = 0; k < 3; ++k) CHECK(m->actuator_gainprm[mjNGAIN * a + k] == r->actuator_gainprm[mjNGAIN * a + k]);
    for (int k = 0; k < 2; ++k) CHECK(m->actuator_biasprm[mjNBIAS * a + k] == r->actuator_biasprm[mjNBIAS * a + k]);
    CHECK(std::abs(m->actuator_biasprm[mjNBIAS * a + 2] - r->actuator_biasprm[mjNBIAS * a + 2]) < 1e-12);
    CHECK(m->actuator_ctrllimited[a] == 1);
    for (int k = 0; k < 2; ++k) CHECK(m->actuator_ctrlrange[2 * a + k] == r->actuator_ctrlrange[2 * a + k]);
    CHECK(m->actuator_forcelimited[a] == r->actuator_forcelimited[a]);
    for (int k = 0; k < 2; ++k) CHECK(m->actuator_forcerange[2 * a + k] == r->actuator_forcerange[2 * a + k]);
  }
  CHECK(m->actuator_biasprm[mjNBIAS * 1 + 2] == -2);
  // The connect: the sites' bodies, site1's position as the anchor, body2's anchor where site2 is.
  CHECK(m->eq_type[0] == mjEQ_CONNECT);
  CHECK(m->eq_obj1id[0] == r->eq_obj1id[0]);
  CHECK(m->eq_obj2id[0] == r->eq_obj2id[0]);
  for (int k = 0; k < 6; ++k) CHECK(std::abs(m->eq_data[k] - r->eq_data[k]) < 1e-15);
  CHECK(m->opt.integrator == mjINT_IMPLICIT);
  const int s2 = mj_name2id(m, mjOBJ_SITE, "closing_C_2");
  for (int k = 0; k < 3; ++k) CHECK(std::abs(m->eq_data[3 + k] - m->site_pos[3 * s2 + k]) < 1e-15);
}

TEST_CASE("the MuJoCo 3 five-bar's loop closes and it moves as the 2.2.2 one does") {
  const model_file::LoadedModel a = model_file::load(writeFile(folder(), "passive3.xml", passive(mujoco3())).string());
  const model_file::LoadedModel b = model_file::load(writeFile(folder(), "passive2.xml", passive(mujoco2(0))).string());
  REQUIRE(a.closures.size() == 1);
  CHECK(a.closures[0].body1 == "left_link");
  CHECK(a.closures[0].body2 == "right_link");
  CHECK(a.dof == 2);
  CHECK(a.q0 == b.q0);
  const bool noted = std::any_of(a.notes.begin(), a.notes.end(), [](const std::string& n) { return n.find("MuJoCo 3 syntax translated") != std::string::npos; });
  CHECK(noted);
  ConstrainedMechanism<Spatial> ma(a.mechanism), mb(b.mechanism);
  CHECK(ma.residual(a.q0) <= 1e-12);
  // 1 s passive from the file's pose at rest: the loop stays closed, the path is the same.
  const std::vector<VecN> pa = passiveRun(ma, a.q0), pb = passiveRun(mb, b.q0);
  REQUIRE(pa.size() == pb.size());
  double dq = 0, dv = 0, gap = 0, swing = 0;
  for (std::size_t k = 0; k < pa.size(); ++k) {
    dq = std::max(dq, maxAbs(pa[k].head(4) - pb[k].head(4)));
    dv = std::max(dv, maxAbs(pa[k].tail(4) - pb[k].tail(4)));
    gap = std::max(gap, ma.residual(pa[k].head(4)));
    swing = std::max(swing, maxAbs(pa[k].head(4) - a.q0));
  }
  MESSAGE("MuJoCo 3 five-bar vs 2.2.2 over 1 s: |dq| " << dq << ", |dv| " << dv << ", |phi| " << gap << ", swing " << swing << " rad");
  CHECK(swing > 0.1);
  CHECK(gap <= 1e-12);
  CHECK(dq <= 1e-12);
  CHECK(dv <= 1e-12);
}

TEST_CASE("an included file's MuJoCo 3 syntax is translated too") {
  std::string text = mujoco3();
  const std::size_t a = text.find("  <actuator>"), b = text.find("</equality>") + std::string("</equality>\n").size();
  const std::string parts = text.substr(a, b - a);
  text.replace(a, b - a, "  <include file=\"parts/servos.xml\"/>\n");
  writeFile(folder(), "parts/servos.xml", "<mujoco>\n" + parts + "</mujoco>\n");
  const auto c = compiled(writeFile(folder(), "included3.xml", text));
  REQUIRE(c->m->nu == 2);
  CHECK(c->m->actuator_biasprm[mjNBIAS * 1 + 2] == -2);
  CHECK(c->m->eq_obj1id[0] == mj_name2id(c->m, mjOBJ_BODY, "left_link"));
}

TEST_CASE("a site-to-site loop open at the reference pose and a later MuJoCo's attribute are refused in one line") {
  const fs::path open = writeFile(folder(), "open3.xml", passive(mujoco3("-0.2 -0.19 0")));
  const std::string e1 = errorOf(open);
  CHECK(e1.find("line ") != std::string::npos);
  CHECK(e1.find("<connect site1='closing_C_1' site2='closing_C_2'>: the loop is not closed at the reference pose (site2 is 0.01 m from site1)") != std::string::npos);
  // A CAD export's rounding (1e-7 m) is read, noted.
  const model_file::LoadedModel rounded = model_file::load(writeFile(folder(), "rounded3.xml", passive(mujoco3("-0.2 -0.2000001 0"))).string());
  CHECK(std::any_of(rounded.notes.begin(), rounded.notes.end(), [](const std::string& n) { return n.find("apart by 1e-07 m") != std::string::npos; }));
  std::string later = passive(mujoco3());
  later.replace(later.find("<joint name=\"right_motor\""), 0, "<joint name=\"extra\" type=\"hinge\" actuatorfrcrange=\"-1 1\"/>\n        ");
  const std::string e2 = errorOf(writeFile(folder(), "later3.xml", later));
  CHECK(e2.find(": line 28: attribute 'actuatorfrcrange' of <joint> is MuJoCo 3.x syntax that Debian's MuJoCo 2.2.2 does not read") != std::string::npos);
}

TEST_CASE("a weld between sites is 2.2.2's weld between their bodies; one whose frames are turned is refused") {
  auto weld = [](std::string text, const std::string& quat) {
    text.replace(text.find("<connect"), std::string("<connect").size(), "<weld");
    text.replace(text.find("quat=\"0 0 0 1\""), std::string("quat=\"0 0 0 1\"").size(), "quat=\"" + quat + "\"");
    return text;
  };
  const auto c = compiled(writeFile(folder(), "weld3.xml", weld(passive(mujoco3()), "1 0 0 0")));
  std::string twin = passive(mujoco2(0));
  twin.replace(twin.find("<connect body1=\"left_link\" body2=\"right_link\" anchor=\"0.2 -0.2 0\"/>"),
               std::string("<connect body1=\"left_link\" body2=\"right_link\" anchor=\"0.2 -0.2 0\"/>").size(),
               "<weld body1=\"left_link\" body2=\"right_link\" anchor=\"-0.2 -0.2 0\"/>");
  const auto r = compiled(writeFile(folder(), "weld2.xml", twin));
  REQUIRE(c->m->neq == 1);
  CHECK(c->m->eq_type[0] == mjEQ_WELD);
  CHECK(c->m->eq_obj1id[0] == r->m->eq_obj1id[0]);
  CHECK(c->m->eq_obj2id[0] == r->m->eq_obj2id[0]);
  for (int k = 0; k < mjNEQDATA; ++k) CHECK(std::abs(c->m->eq_data[k] - r->m->eq_data[k]) < 1e-15);
  // Loaded, the same closure as the twin's (its rows are issue 40 item 1's: a loop in the x-z plane).
  const model_file::LoadedModel a = model_file::load(writeFile(folder(), "weld3.xml", weld(passive(mujoco3()), "1 0 0 0")).string());
  const model_file::LoadedModel b = model_file::load(writeFile(folder(), "weld2.xml", twin).string());
  REQUIRE(a.closures.size() == 1);
  CHECK(a.closures[0].kind == "weld");
  CHECK(a.closures[0].kept == b.closures[0].kept);
  CHECK(a.dof == b.dof);
  CHECK(ConstrainedMechanism<Spatial>(a.mechanism).residual(a.q0) <= 1e-12);
  const std::string e = errorOf(writeFile(folder(), "turned3.xml", weld(passive(mujoco3()), "0 0 0 1")));
  CHECK(e.find("<weld site1='closing_C_1' site2='closing_C_2'>: the loop is not closed at the reference pose (site2 is ") != std::string::npos);
  CHECK(e.find("m from site1, turned 3.14 rad)") !=
        std::string::npos);
}

TEST_CASE("MuJoCo's own error in a translated file names the line as the file writes it") {
  std::string text = passive(mujoco3());
  // An element over several lines before the error (the translation prints it on one), then a bad keyword.
  const std::string option = "<option noslip_iterations=\"1\" integrator=\"implicitfast\"></option>";
  text.replace(text.find(option), option.size(), "<option\n      noslip_iterations=\"1\"\n\n  />");
  const std::size_t bad = text.find("type=\"hinge\"/>\n          <inertial pos=\"-0.1");
  REQUIRE(bad != std::string::npos);
  text.replace(bad, std::string("type=\"hinge\"").size(), "type=\"hing\"");
  const long line = 1 + std::count(text.begin(), text.begin() + long(bad), '\n');
  const std::string e = errorOf(writeFile(folder(), "keyword3.xml", text));
  CHECK(e.find("invalid keyword: 'hing' Element 'joint', line " + std::to_string(line)) != std::string::npos);
}
