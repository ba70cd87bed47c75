// The one bound on a run's work (labs/settings.h: steps = duration / dt, the trace's memory, the frames
// drawn), through the real binary on every path that asks for a run: a model file's <option timestep>
// (figure, bench), --duration on a model file and on a lab, a lab's JSON, a wide model's trace, a
// video's frames. Each is refused up front with exit 2 and one line naming the bound, quickly (the
// refusal comes before anything runs), never std::bad_alloc or exit 3.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include <regex>

#include "tests/app/cli_run.h"
#include "tests/app/limited_run.h"

using dyn::test::cli::TempDir;
using namespace dyn::test::limited;

namespace {

std::string modelPath(const char* name) { return std::string(DYNLAB_SOURCE_DIR) + "/assets/models/" + name; }

// The four-bar with another <option timestep>.
void writeFourbar(const fs::path& file, const std::string& timestep) {
  std::string text = slurp(modelPath("fourbar.xml"));
  text = std::regex_replace(text, std::regex("timestep=\"0.001\""), "timestep=\"" + timestep + "\"");
  std::ofstream(file, std::ios::binary) << text;
}

// A chain of n hinges (bodies that do not collide): a wide trace row (t, q, v, energy, work, residual).
void writeChain(const fs::path& file, int n) {
  std::string bodies, ends;
  for (int i = 0; i < n; ++i) {
    bodies += "<body pos=\"0 0 0.1\"><joint name=\"j" + std::to_string(i) + "\" type=\"hinge\" axis=\"0 1 0\"/>"
              "<geom type=\"capsule\" fromto=\"0 0 0 0 0 0.1\" size=\"0.01\" mass=\"0.1\" contype=\"0\" conaffinity=\"0\"/>";
    ends += "</body>";
  }
  std::ofstream(file, std::ios::binary) << "<mujoco><option timestep=\"0.001\"/><worldbody>" + bodies + ends + "</worldbody></mujoco>";
}

// Exit 2, one line on stderr holding every part, nothing on it from a crash, within `seconds`.
void refused(const Ended& r, const std::vector<std::string>& parts, double seconds = 20) {
  INFO("stderr: " << r.err);
  CHECK(r.signal == 0);
  CHECK(r.code == 2);
  CHECK(lineCount(r.err) == 1);
  for (const auto& p : parts) CHECK_MESSAGE(r.err.find(p) != std::string::npos, "missing: " << p);
  CHECK(r.err.find("bad_alloc") == std::string::npos);
  CHECK(r.seconds < seconds);
}

const std::string kBound = "more than the 2e+06 a run may take";

}  // namespace

TEST_CASE("a model file's timestep of 1e-9 is refused by figure and bench, the bound named") {
  TempDir dir("bounds_timestep");
  writeFourbar(dir / "f.xml", "1e-9");
  const std::string sentence = "timestep 1e-09 s over 2 s is 2e+09 steps, " + kBound;
  refused(runDynlab(dir.path, {"figure", "f.xml", "--out", "o"}), {"f.xml", "<option timestep>", sentence});
  refused(runDynlab(dir.path, {"bench", "f.xml"}), {"f.xml", "<option timestep>", sentence});
  CHECK(!fs::exists(dir / "o"));
  // `model` and `run FILE` step at --dt, not at the file's timestep: their bound is --duration / --dt.
  refused(runDynlab(dir.path, {"model", "f.xml", "--dt", "1e-5", "--duration", "600", "--out", "o"}),
          {"--duration", "dt 1e-05 s over 600 s is 6e+07 steps, " + kBound});
}

TEST_CASE("--duration on a model file and on a lab is bounded by its steps, named as the option") {
  TempDir dir("bounds_duration");
  refused(runDynlab(dir.path, {"figure", modelPath("fourbar.xml"), "--duration", "100000", "--out", "o"}),
          {"<command line>", "--duration", "fourbar.xml's timestep 0.001 s over 100000 s is 1e+08 steps, " + kBound});
  refused(runDynlab(dir.path, {"run", "slider_crank", "--duration", "3600", "--out", "o"}),
          {"<command line>", "--duration", "dt 0.001 s over 3600 s is 3.6e+06 steps, " + kBound});
  refused(runDynlab(dir.path, {"figure", "slider_crank", "--duration", "3600", "--out", "o"}),
          {"--duration", "3.6e+06 steps, " + kBound});
  CHECK(!fs::exists(dir / "o"));
}

TEST_CASE("a lab's JSON: the same bound, at its JSON path") {
  TempDir dir("bounds_json");
  const std::string config = slurp(std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/slider_crank.json");
  nlohmann::json c = nlohmann::json::parse(config);
  c["simulation"]["dt"] = 1e-6;
  c["simulation"]["duration"] = 10.0;
  std::ofstream(dir / "c.json") << c.dump();
  refused(runDynlab(dir.path, {"run", "slider_crank", "--config", "c.json", "--out", "o"}),
          {"c.json", "/simulation/duration", "dt 1e-06 s over 10 s is 1e+07 steps, " + kBound});
}

TEST_CASE("a wide model's trace memory and a video's frames are bounded too") {
  TempDir dir("bounds_memory");
  writeChain(dir / "chain.xml", 24);  // dynlab's most joints: a row of t, q, v, energy, work, residual
  refused(runDynlab(dir.path, {"model", "chain.xml", "--duration", "600", "--dt", "4e-4", "--out", "o"}),
          {"--duration", "a trace of 1.5e+06 rows × 52 columns is 624 MB, more than the 512 MB a run's trace may hold"});
  // The model file's lab adds each joint's bearing load (3 columns a joint).
  refused(runDynlab(dir.path, {"figure", "chain.xml", "--duration", "600", "--out", "o"}),
          {"--duration", "a trace of 600001 rows × 124 columns is 595 MB, more than the 512 MB a run's trace may hold (chain.xml's timestep 0.001 s"});
  // 1500 s at 30 frames a second: 45,001 frames, refused before the run (1.5e6 steps are allowed).
  refused(runDynlab(dir.path, {"run", "slider_crank", "--duration", "1500", "--video", "--out", "o"}),
          {"--video", "1500 s at 30 frames a second is 45001 frames, more than the 36000 a run may draw"});
  CHECK(!fs::exists(dir / "o"));
}
