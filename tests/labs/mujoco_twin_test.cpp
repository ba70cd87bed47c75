// Each C++ lab's mechanism written for MuJoCo (labs/<name>/mujoco.xml, which dynlab bench times) is the lab's
// own mechanism: MuJoCo's M(q) (mj_fullM) and bias C(q, v) v + G(q) (qfrc_bias) from the file equal the
// hand model's CRBA and RNEA (plus its payloads) to 1e-9 relative at the lab's start and at configurations
// and rates away from it, in the file's coordinates (Lab::mujocoTwin's map). A file with one mass changed
// is caught, and every data lab offers its own model file.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

#include "labs/lab.h"
#include "labs/run.h"
#include "physics/model_file/model_file.h"

using namespace dyn;
namespace fs = std::filesystem;

namespace {

const char* const kLabs[] = {"grasp", "unicycle", "impedance", "motion_control", "pen_on_table", "slider_crank"};

std::string folderOf(const std::string& lab) { return std::string(DYNLAB_SOURCE_DIR) + "/labs/" + lab; }

// The largest disagreement of M and the bias, relative to their own largest entries, over the lab's
// start and three configurations away from it (rates made up: every Coriolis term exercised).
struct Gap {
  double mass = 0, bias = 0;
};
Gap compare(const MujocoTwin& twin, const model_file::LoadedModel& file) {
  model_file::MujocoReference mujoco(file);
  const int n = int(twin.q.size());
  REQUIRE(mujoco.nv() == n);
  REQUIRE(file.q0.size() == n);  // no quaternions: q and v in the same coordinates
  Gap gap;
  for (int k = 0; k < 4; ++k) {
    VecN q = twin.q, v = twin.v;
    for (int i = 0; i < n; ++i) {
      q[i] += k == 0 ? 0.0 : 0.3 * std::sin(1.7 * k + 0.9 * i);
      v[i] += k == 0 ? 0.0 : 1.5 * std::cos(2.3 * k + 1.1 * i);
    }
    MatN M;
    VecN bias;
    twin.dynamics(q, v, M, bias);
    const MatN Mf = mujoco.massMatrix(twin.toFile(q));
    const VecN bf = mujoco.bias(twin.toFile(q), twin.toFile(v));
    double m_diff = 0, b_diff = 0;
    for (int i = 0; i < n; ++i) {
      const int li = twin.order.empty() ? i : twin.order[std::size_t(i)];
      b_diff = std::max(b_diff, std::abs(bf[i] - bias[li]));
      for (int j = 0; j < n; ++j) {
        const int lj = twin.order.empty() ? j : twin.order[std::size_t(j)];
        m_diff = std::max(m_diff, std::abs(Mf(i, j) - M(li, lj)));
      }
    }
    gap.mass = std::max(gap.mass, m_diff / M.cwiseAbs().maxCoeff());
    gap.bias = std::max(gap.bias, b_diff / std::max(1e-12, bias.cwiseAbs().maxCoeff()));
  }
  return gap;
}

}  // namespace

TEST_CASE("each C++ lab's MuJoCo file is the lab's mechanism: M and bias equal to 1e-9") {
  for (const char* name : kLabs) {
    CAPTURE(name);
    const LoadedLab loaded = loadLab(name);
    const MujocoTwin twin = loaded.lab->mujocoTwin();
    REQUIRE(twin.file == "mujoco.xml");
    REQUIRE(twin.dynamics);
    const model_file::LoadedModel file = model_file::load(folderOf(name) + "/" + twin.file);
    const Gap gap = compare(twin, file);
    CHECK(gap.mass < 1e-9);
    CHECK(gap.bias < 1e-9);
    // The start is where the file's loops hold (MuJoCo's own kinematics).
    const double closure = model_file::MujocoReference(file).closure(twin.toFile(twin.q));
    CHECK(closure < 1e-9);
  }
}

TEST_CASE("a MuJoCo file with one mass changed is caught") {
  const LoadedLab loaded = loadLab("slider_crank");
  const MujocoTwin twin = loaded.lab->mujocoTwin();
  std::ifstream in(folderOf("slider_crank") + "/mujoco.xml");
  std::stringstream text;
  text << in.rdbuf();
  std::string xml = text.str();
  const std::string from = "mass=\"1.5\"";
  REQUIRE(xml.find(from) != std::string::npos);
  xml.replace(xml.find(from), from.size(), "mass=\"1.5000001\"");  // the coupler 0.1 g heavier
  const fs::path dir = fs::temp_directory_path() / ("dynlab-mujoco-twin-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "mujoco.xml") << xml;
  const Gap gap = compare(twin, model_file::load((dir / "mujoco.xml").string()));
  fs::remove_all(dir);
  CHECK(gap.mass > 1e-8);
}

TEST_CASE("every data lab offers its own model file to MuJoCo") {
  for (const char* name : {"fivebar", "puma_motion", "puma_impedance"}) {
    CAPTURE(name);
    const LoadedLab loaded = loadLab(name);
    const MujocoTwin twin = loaded.lab->mujocoTwin();
    REQUIRE(twin.loaded);
    CHECK(twin.q.size() == twin.loaded->q0.size());
    CHECK(twin.v.size() == twin.loaded->mechanism.treeDof());
  }
}
