// Tests for the Gradescope image (issue 41 item 10): scripts/autograder-packages, run for real
// against a fake apt-cache on PATH (which packages an image offers, at which version), picks only
// what grading needs, names a missing required package in one line, and turns what is missing or
// unneeded into CMake options; the zip's setup.sh and README follow the lab (a model file needs
// MuJoCo); and CMake configures the reduced dynlab those options ask for (configure only: quick).
#include <doctest/doctest.h>
#include <zip.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "app/cli/course/autograder.h"
#include "app/shared/process.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;
using dyn::test::readBytes;

namespace {

fs::path scratch(const std::string& name) { return dyn::test::scratchDir("dynlab_gradescope_image_test", name); }

void writeText(const fs::path& p, const std::string& text, bool exec = false) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
  if (exec) fs::permissions(p, fs::perms::owner_all | fs::perms::group_read | fs::perms::others_read);
}

// What grading needs on every image, as autograder-packages lists it.
const std::vector<std::string> kRequired = {
    "build-essential", "cmake", "pkg-config", "libeigen3-dev", "libbullet-dev", "libosmesa6-dev", "libimgui-dev", "libstb-dev",
    "nlohmann-json3-dev", "libcli11-dev", "fonts-dejavu-core", "libplplot-dev", "plplot-driver-cairo", "libcairo2-dev", "libzip-dev",
    "zlib1g-dev", "libcmark-gfm-dev", "libcmark-gfm-extensions-dev", "libssl-dev"};

// An image's package lists: name → candidate version ("(none)": known, not installable).
using Image = std::map<std::string, std::string>;

Image everything(const std::string& gxx) {
  Image image;
  for (const auto& p : kRequired) image[p] = "1.0";
  image["libmujoco-dev"] = "2.2.2-3";
  image["libtinyxml2-dev"] = "9.0.0+dfsg-3";
  image["g++"] = gxx;
  return image;
}

struct Choice {
  int code = -1;
  std::set<std::string> packages, options;
  std::string err;
};

std::set<std::string> words(const std::string& line) {
  std::istringstream in(line);
  std::set<std::string> out;
  for (std::string w; in >> w;) out.insert(w);
  return out;
}

// Runs the tree's scripts/autograder-packages (args) with a fake apt-cache that knows `image`.
Choice choose(const Image& image, const std::vector<std::string>& args = {}) {
  const fs::path dir = scratch("choose");
  std::string lists;
  for (const auto& [name, version] : image) lists += name + " " + version + "\n";
  writeText(dir / "lists.txt", lists);
  // `apt-cache policy NAME`, as apt prints it: nothing for a name the lists do not have.
  writeText(dir / "bin" / "apt-cache",
            "#!/usr/bin/env bash\n[ \"$1\" = policy ] || exit 100\n"
            "while read -r name version; do\n"
            "  if [ \"$name\" = \"$2\" ]; then printf '%s:\\n  Installed: (none)\\n  Candidate: %s\\n' \"$name\" \"$version\"; fi\n"
            "done < '" + (dir / "lists.txt").string() + "'\n",
            true);
  std::vector<std::string> argv = {"bash", std::string(DYNLAB_SOURCE_DIR) + "/scripts/autograder-packages"};
  argv.insert(argv.end(), args.begin(), args.end());
  dyn::ProcessOptions o;
  const char* path = std::getenv("PATH");
  o.set_env = {{"PATH", (dir / "bin").string() + ":" + (path ? path : "/usr/bin:/bin")}};
  o.stdout_file = (dir / "out.txt").string();
  o.stderr_file = (dir / "err.txt").string();
  o.timeout_s = 60;
  Choice c;
  c.code = dyn::runProgram(argv, o).code;
  c.err = readBytes(dir / "err.txt");
  std::istringstream out(readBytes(dir / "out.txt"));
  for (std::string line; std::getline(out, line);) {
    if (line.rfind("packages: ", 0) == 0) c.packages = words(line.substr(10));
    if (line.rfind("cmake: ", 0) == 0) c.options = words(line.substr(7));
  }
  return c;
}

// Every line of text that is not empty.
int lines(const std::string& text) {
  int n = 0;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) n += !line.empty();
  return n;
}

// One entry of a zip written by writeAutograder.
std::string zipEntry(const fs::path& zip, const std::string& name) {
  int err = 0;
  zip_t* za = zip_open(zip.string().c_str(), ZIP_RDONLY, &err);
  REQUIRE(za != nullptr);
  zip_stat_t st;
  REQUIRE(zip_stat(za, name.c_str(), 0, &st) == 0);
  std::string data(st.size, '\0');
  zip_file_t* f = zip_fopen(za, name.c_str(), 0);
  REQUIRE(f != nullptr);
  REQUIRE(zip_fread(f, data.data(), st.size) == static_cast<zip_int64_t>(st.size));
  zip_fclose(f);
  zip_close(za);
  return data;
}

}  // namespace

TEST_CASE("autograder-packages: only what grading needs, and a dynlab without tests, video or (no model file) MuJoCo") {
  const Choice c = choose(everything("4:12.2.0-3"));
  CHECK(c.code == 0);
  CHECK(c.packages == std::set<std::string>(kRequired.begin(), kRequired.end()));
  for (const char* unneeded : {"libglfw3-dev", "libavcodec-dev", "python3-dev", "pybind11-dev", "doctest-dev", "xvfb", "libmujoco-dev"})
    CHECK_MESSAGE(!c.packages.count(unneeded), unneeded);
  CHECK(c.options == std::set<std::string>{"-DDYNLAB_WITH_TESTS=OFF", "-DDYNLAB_WITH_VIDEO=OFF", "-DDYNLAB_WITH_MUJOCO=OFF"});
}

TEST_CASE("autograder-packages: a lab with a model file installs MuJoCo's parser and builds with it") {
  const Choice c = choose(everything("4:12.2.0-3"), {"--model-files"});
  CHECK(c.code == 0);
  CHECK(c.packages.count("libmujoco-dev"));
  CHECK(c.packages.count("libtinyxml2-dev"));
  CHECK(!c.options.count("-DDYNLAB_WITH_MUJOCO=OFF"));
}

TEST_CASE("autograder-packages: an image without libmujoco-dev still builds a hand-written lab, never a data lab") {
  Image image = everything("4:12.2.0-3");
  image.erase("libmujoco-dev");
  CHECK(choose(image).code == 0);
  const Choice data = choose(image, {"--model-files"});
  CHECK(data.code == 1);
  CHECK(data.packages.empty());
  CHECK(lines(data.err) == 1);
  CHECK(data.err.find("no libmujoco-dev") != std::string::npos);
  CHECK(data.err.find("model file") != std::string::npos);
  // Known to the lists but without a candidate counts as missing too.
  image["libmujoco-dev"] = "(none)";
  CHECK(choose(image, {"--model-files"}).code == 1);
}

TEST_CASE("autograder-packages: a required package the image lacks is named in one line, and nothing is chosen") {
  Image image = everything("4:12.2.0-3");
  image.erase("libimgui-dev");
  image.erase("libcmark-gfm-dev");
  const Choice c = choose(image);
  CHECK(c.code == 1);
  CHECK(c.packages.empty());
  CHECK(lines(c.err) == 1);
  CHECK(c.err.find("libimgui-dev") != std::string::npos);
  CHECK(c.err.find("libcmark-gfm-dev") != std::string::npos);
  CHECK(c.err.find("Which base image") != std::string::npos);
}

TEST_CASE("autograder-packages: a default g++ older than 12 is replaced by g++-12 when the image has it") {
  Image image = everything("4:11.2.0-1ubuntu1");
  image["g++-12"] = "12.3.0-1ubuntu1~22.04";
  image["gcc-12"] = "12.3.0-1ubuntu1~22.04";
  const Choice c = choose(image);
  CHECK(c.code == 0);
  CHECK(c.packages.count("g++-12"));
  CHECK(c.options.count("-DCMAKE_CXX_COMPILER=g++-12"));
  CHECK(c.options.count("-DCMAKE_C_COMPILER=gcc-12"));
  // Without g++-12 the default is tried (and said so); with g++ 12 nothing changes.
  image.erase("g++-12");
  const Choice old = choose(image);
  CHECK(old.code == 0);
  CHECK(!old.options.count("-DCMAKE_CXX_COMPILER=g++-12"));
  CHECK(old.err.find("no g++-12") != std::string::npos);
  CHECK(!choose(everything("4:12.2.0-3")).packages.count("g++-12"));
}

TEST_CASE("autograder-packages: an unknown argument is refused") {
  const Choice c = choose(everything("4:12.2.0-3"), {"--everything"});
  CHECK(c.code == 2);
  CHECK(lines(c.err) == 1);
}

TEST_CASE("the zip's setup.sh and README follow the lab: a model file asks for MuJoCo") {
  const fs::path dir = scratch("zips");
  dyn::app::writeAutograder("slider_crank", DYNLAB_SOURCE_DIR, (dir / "slider_crank.zip").string());
  ::setenv("DYNLAB_COURSE_SECRET", "gradescope-image-test", 1);  // fivebar gives each student a plant
  dyn::app::writeAutograder("fivebar", DYNLAB_SOURCE_DIR, (dir / "fivebar.zip").string());
  ::unsetenv("DYNLAB_COURSE_SECRET");
  const std::string hand = zipEntry(dir / "slider_crank.zip", "setup.sh"), data = zipEntry(dir / "fivebar.zip", "setup.sh");
  for (const std::string* setup : {&hand, &data}) {
    CHECK(setup->find("scripts/autograder-packages") != std::string::npos);
    CHECK(setup->find("\"${options[@]}\"") != std::string::npos);
    CHECK(setup->find("bullet-float64") != std::string::npos);
    CHECK(setup->find("scripts/setup\"") == std::string::npos);  // not the developers' full list
  }
  CHECK(hand.find("autograder-packages\" --model-files") == std::string::npos);
  CHECK(data.find("autograder-packages\" --model-files") != std::string::npos);
  const std::string hand_readme = zipEntry(dir / "slider_crank.zip", "README.md");
  const std::string data_readme = zipEntry(dir / "fivebar.zip", "README.md");
  CHECK(hand_readme.find("it needs no MuJoCo") != std::string::npos);
  CHECK(data_readme.find("`libmujoco-dev`; if setup.sh stops") != std::string::npos);
  CHECK(hand_readme.find("libmujoco-dev") == std::string::npos);
  CHECK(data_readme.find("@") == std::string::npos);  // every placeholder filled
  CHECK(fs::is_regular_file(fs::path(DYNLAB_SOURCE_DIR) / "scripts" / "autograder-packages"));
}

TEST_CASE("CMake configures the reduced dynlab: no tests, no video, no MuJoCo") {
  const fs::path dir = scratch("configure");
  dyn::ProcessOptions o;
  o.stdout_file = o.stderr_file = (dir / "log.txt").string();
  o.append = true;
  o.timeout_s = 120;
  const auto r = dyn::runProgram({DYNLAB_CMAKE_COMMAND, "-S", DYNLAB_SOURCE_DIR, "-B", (dir / "build").string(), "-DCMAKE_BUILD_TYPE=Release",
                                  "-DDYNLAB_WITH_TESTS=OFF", "-DDYNLAB_WITH_VIDEO=OFF", "-DDYNLAB_WITH_MUJOCO=OFF"},
                                 o);
  INFO(readBytes(dir / "log.txt"));
  REQUIRE(r.code == 0);
  const std::string cache = readBytes(dir / "build" / "CMakeCache.txt");
  CHECK(cache.find("DYNLAB_WITH_MUJOCO:BOOL=OFF") != std::string::npos);
  // No test programs, and the model-file library made of the stand-in, not MuJoCo's calls.
  CHECK(!fs::exists(dir / "build" / "tests"));
  const std::string model_file = readBytes(dir / "build" / "physics" / "model_file" / "CMakeFiles" / "dynlab_model_file.dir" / "build.make");
  CHECK(model_file.find("without_mujoco.cpp") != std::string::npos);
  CHECK(model_file.find("mujoco_call.cpp") == std::string::npos);
  const std::string render = readBytes(dir / "build" / "render" / "CMakeFiles" / "dynlab_render.dir" / "build.make");
  CHECK(render.find("video_none.cpp") != std::string::npos);
  CHECK(render.find("/video.cpp") == std::string::npos);
  fs::remove_all(dir);
}
