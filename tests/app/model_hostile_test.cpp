// Hostile model files through the real binary (issue 39, items 2 to 4): a file MuJoCo's parser
// crashes on (47,000 bodies) or runs away with (100,000 bodies) is refused in one line within 5 s; a
// model reached through a link in another folder, its <include> beside the link's target, is read
// once from the checked files by the load, the M/h cross-check and bench's MuJoCo engine alike (no
// "Include error", no hang on a FIFO beside the link). The files are made here, at run time. The
// binary runs from an argument vector (app/shared/process.h, no shell) with a deadline: a hang fails the
// test instead of stalling it.
#include <doctest/doctest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "app/shared/process.h"

namespace {

namespace fs = std::filesystem;

struct Run {
  int code = -1;  // exit status; 128 + N for signal N; -1 if killed at the deadline
  std::string out, err;
  double seconds = 0;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// dynlab with these arguments in folder dir, killed after `limit` seconds (app/shared/process.h: no shell).
Run dynlab(const fs::path& dir, const std::vector<std::string>& args, double limit) {
  const fs::path out = dir / ".stdout", err = dir / ".stderr";
  std::vector<std::string> argv{DYNLAB_BIN};
  argv.insert(argv.end(), args.begin(), args.end());
  dyn::ProcessOptions o;
  o.cwd = dir.string(), o.stdout_file = out.string(), o.stderr_file = err.string(), o.timeout_s = limit;
  const auto t0 = std::chrono::steady_clock::now();
  const dyn::ProcessResult p = dyn::runProgram(argv, o);
  REQUIRE_MESSAGE(p.started(), p.error);
  Run r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.code = p.timed_out ? -1 : p.code;
  r.out = slurp(out), r.err = slurp(err);
  fs::remove(out), fs::remove(err);
  return r;
}

struct Dir {
  fs::path path;
  explicit Dir(const std::string& name) : path(fs::path(DYNLAB_TEST_TMP) / ("hostile_model_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~Dir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

void write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

// `count` bodies, each with a geom: MuJoCo 2.2.2's parser crashes on 47,000 and takes 92 s and 1.7 GB
// on 100,000.
std::string manyBodies(int count) {
  std::string s = "<mujoco><worldbody><body name=\"arm\"><joint name=\"j\"/><geom size=\"0.1\"/></body>";
  for (int i = 0; i < count; ++i) s += "<body><geom/></body>";
  return s + "</worldbody></mujoco>";
}

// The refusal contract: exit 2, one line naming the file, nothing on stdout, nothing written.
void refused(const Run& r, const std::string& file, const std::string& what) {
  INFO("stderr: ", r.err, "\nstdout: ", r.out.substr(0, 400), "\ncode ", r.code, " after ", r.seconds, " s");
  CHECK(r.code == 2);
  CHECK(r.out.empty());
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK(r.err.find(file) != std::string::npos);
  CHECK(r.err.find(what) != std::string::npos);
}

// `dynlab model FILE` on a folder holding only FILE with this text: refused as above, nothing written.
void refusesFile(const std::string& folder, const std::string& file, const std::string& text, const std::string& what) {
  Dir dir(folder);
  write(dir.path / file, text);
  const Run r = dynlab(dir.path, {"model", file, "--out", "o"}, 60);
  refused(r, file, what);
  CHECK_FALSE(fs::exists(dir.path / "o"));
}

// A pendulum whose body sits in an included file.
const char* kPendulum =
    "<mujoco model=\"pend\"><option><flag contact=\"disable\"/></option><worldbody><include file=\"arm.xml\"/></worldbody></mujoco>";
const char* kArm = "<mujoco><body name=\"arm\"><joint name=\"swing\" axis=\"0 1 0\"/><geom type=\"capsule\" fromto=\"0 0 0 0 0 -0.5\" size=\"0.02\"/></body></mujoco>";

}  // namespace

TEST_CASE("dynlab model on 47,000 and 100,000 bodies: refused in one line within 5 s, naming the count and the limit") {
  Dir dir("bodies");
  for (int count : {47000, 100000}) {
    const std::string name = "bodies" + std::to_string(count) + ".xml";
    write(dir.path / name, manyBodies(count));
    const Run r = dynlab(dir.path, {"model", name, "--out", "o"}, 60);
    refused(r, name, std::to_string(count + 1) + " bodies, more than the 1000 a model file may have");
    CHECK(r.seconds < 5);
    CHECK_FALSE(fs::exists(dir.path / "o"));
  }
}

TEST_CASE("a model reached through a link: the load, the cross-check and bench's MuJoCo read the same checked files") {
  // real/pend.xml includes arm.xml beside it; view/pend.xml links to it from another folder, where
  // MuJoCo would look for arm.xml if it read the disk again.
  Dir dir("link");
  write(dir.path / "real/pend.xml", kPendulum);
  write(dir.path / "real/arm.xml", kArm);
  fs::create_directories(dir.path / "view");
  fs::create_symlink("../real/pend.xml", dir.path / "view/pend.xml");
  const Run m = dynlab(dir.path, {"model", "view/pend.xml", "--duration", "0.1", "--engine", "hand", "--out", "o"}, 60);
  INFO("stderr: ", m.err);
  CHECK(m.code == 0);
  CHECK(m.out.find("against MuJoCo") != std::string::npos);
  const Run b = dynlab(dir.path, {"bench", "view/pend.xml", "--steps", "100"}, 60);
  INFO("bench stderr: ", b.err);
  CHECK(b.code == 0);
  CHECK(b.out.find("MuJoCo 2.2.2 mj_step") != std::string::npos);
  // A FIFO where a second read would look (beside the link): nobody opens it, nothing hangs.
  REQUIRE(::mkfifo((dir.path / "view/arm.xml").c_str(), 0600) == 0);
  const Run f = dynlab(dir.path, {"model", "view/pend.xml", "--duration", "0.1", "--engine", "hand", "--out", "o2"}, 60);
  INFO("fifo stderr: ", f.err);
  CHECK(f.code == 0);
  CHECK(f.seconds < 30);
  const Run fb = dynlab(dir.path, {"bench", "view/pend.xml", "--steps", "100"}, 60);
  CHECK(fb.code == 0);
}

TEST_CASE("a file that makes MuJoCo's parser exhaust its memory is refused in one line, the limit named") {
  // A height field of 20000 x 20000 samples: 1.6 GB of floats MuJoCo's compiler would allocate.
  refusesFile("memory", "field.xml",
              "<mujoco><asset><hfield name=\"h\" nrow=\"20000\" ncol=\"20000\" size=\"1 1 1 1\"/></asset><worldbody><body><joint/>"
              "<geom size=\"0.1\"/></body></worldbody></mujoco>",
              "MuJoCo's parser ran out of memory on this file (limit 1024 MiB)");
}

TEST_CASE("a URDF that is not well-formed XML (a <mimic> and a visual mesh in it) is refused in one line, exit 2") {
  refusesFile("broken_urdf", "broken.urdf",
              "<robot name=\"a\"><link name=\"b\"><visual><geometry><mesh filename=\"m.stl\"/></geometry></visual>\n"
              "<joint name=\"j\" type=\"revolute\"><parent link=\"b\"/><mimic joint=\"k\"/></joint></robot>",
              "XML parse error");
}
