// Names and paths from files are shown escaped and clipped, never raw: model files whose joint,
// body and closure names hold ESC, BEL, U+202E (a bidi override) and U+009B (a C1 CSI), or 200,000
// characters; a broken model file named with an OSC sequence or a newline; `new-lab` given a name
// with a newline. Every file is written here at run time, and the binary is run with an argument
// vector (fork/exec: no shell), so any byte reaches it as given. Bound messages print the value
// refused with the digits that show why (20000.000000000004, not 2e+04).
#include <doctest/doctest.h>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "tests/app/cli_run.h"

using namespace dyn::test::cli;

namespace {

// The bytes a terminal acts on: C0 controls other than a line's newline (ESC, BEL, CR), DEL, a C1
// control written in UTF-8 (U+0080–U+009F: C2 80–C2 9F) and the bidi overrides U+202A–U+202E.
bool hasControl(const std::string& s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]), next = i + 1 < s.size() ? static_cast<unsigned char>(s[i + 1]) : 0;
    if ((c < 0x20 && c != '\n') || c == 0x7F) return true;
    if (c == 0xC2 && next >= 0x80 && next <= 0x9F) return true;
    if (c == 0xE2 && next == 0x80 && i + 2 < s.size() && static_cast<unsigned char>(s[i + 2]) >= 0xAA &&
        static_cast<unsigned char>(s[i + 2]) <= 0xAE)
      return true;
  }
  return false;
}

std::size_t lines(const std::string& s) { return std::size_t(std::count(s.begin(), s.end(), '\n')); }

// The shipped four-bar with its crank joint, coupler body and closure named as given (XML-escaped).
std::string fourbar(const std::string& joint, const std::string& body, const std::string& closure) {
  const auto attr = [](const std::string& s) {
    std::string out;
    for (char c : s) out += c == '"' ? std::string("&quot;") : c == '&' ? std::string("&amp;") : c == '<' ? std::string("&lt;") : std::string(1, c);
    return out;
  };
  return R"(<mujoco model="fourbar">
  <option gravity="0 0 -9.81" timestep="0.001"/>
  <default><geom type="capsule" size="0.015" contype="0" conaffinity="0"/></default>
  <worldbody>
    <body name="crank">
      <joint name=")" + attr(joint) + R"(" type="hinge" axis="0 1 0"/>
      <geom fromto="0 0 0 0 0 0.2" mass="0.2"/>
      <body name=")" + attr(body) + R"(" pos="0 0 0.2">
        <joint name="coupler" type="hinge" axis="0 1 0"/>
        <geom fromto="0 0 0 0.4 0 0.1" mass="0.4"/>
      </body>
    </body>
    <body name="rocker" pos="0.5 0 0">
      <joint name="rocker" type="hinge" axis="0 1 0"/>
      <geom fromto="0 0 0 -0.1 0 0.3" mass="0.3"/>
    </body>
  </worldbody>
  <equality>
    <connect name=")" + attr(closure) + R"(" body1=")" + attr(body) + R"(" body2="rocker" anchor="0.4 0 0.1"/>
  </equality>
</mujoco>
)";
}

const std::string kHostile = "x\x1b]0;pwned\x07y\xe2\x80\xae" "z\xc2\x9b" "31m";  // ESC OSC … BEL, U+202E, U+009B

}  // namespace

TEST_CASE("dynlab model: joint, body and closure names with ESC, BEL, U+202E, U+009B are printed escaped, also in summary.txt") {
  const TempDir dir("names_hostile");
  writeFile(dir / "hostile.xml", fourbar("crank" + kHostile, "coupler" + kHostile, "pin" + kHostile));
  const Result r = dynlab(dir, {"model", "hostile.xml", "--duration", "0.01", "--out", "out"});
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  CHECK_FALSE(hasControl(r.out));
  CHECK_FALSE(hasControl(r.err));
  // Shown, as escapes: the reader sees what the file holds.
  CHECK(r.out.find("joint crankx\\x1B]0;pwned\\x07y\\u{202E}z\\u{009B}31m (hinge") != std::string::npos);
  CHECK(r.out.find("closure pin") != std::string::npos);
  const std::string summary = readFile(dir / "out/summary.txt");
  REQUIRE_FALSE(summary.empty());
  CHECK_FALSE(hasControl(summary));
  CHECK(summary.find("\\x1B]0;pwned\\x07") != std::string::npos);
  // The trace's header: the names as column names (letters, digits, _), no control byte.
  const std::string trace = readFile(dir / "out/trace.csv");
  CHECK_FALSE(hasControl(trace.substr(0, trace.find('\n'))));
}

TEST_CASE("dynlab model: a 200,000-character joint name is clipped on the terminal, in summary.txt and in the trace's header") {
  const TempDir dir("names_long");
  const std::string name = "j" + std::string(200000, 'a');
  writeFile(dir / "long.xml", fourbar(name, "coupler", "pin_C"));
  const Result r = dynlab(dir, {"model", "long.xml", "--duration", "0.01", "--out", "out"});
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(r.out.size() < 20000);  // today: the name in full, 200 kB
  CHECK(r.out.find("bytes left out") != std::string::npos);
  CHECK(readFile(dir / "out/summary.txt").size() < 20000);
  const std::string trace = readFile(dir / "out/trace.csv"), header = trace.substr(0, trace.find('\n'));
  CHECK(header.size() < 2000);
  // Still one column per joint: q_ and v_ of the long name, each once.
  const Csv csv = readCsv(dir / "out/trace.csv");
  std::size_t long_columns = 0;
  for (const auto& c : csv.header) long_columns += c.size() > 40;
  CHECK(long_columns == 2);
}

TEST_CASE("dynlab model: a broken model file named with an OSC sequence or a newline gets one escaped line on stderr") {
  const TempDir dir("names_path");
  for (const std::string& file : {std::string("bad\x1b]0;pwned\x07.xml"), std::string("bad\nsecond line.xml"), std::string("bad\xe2\x80\xae.xml")}) {
    writeFile(dir / file, "<mujoco><worldbody><body name=\"b\"><joint name=\"j\" type=\"hinge\"/>");  // cut short
    for (const std::vector<std::string>& args : {std::vector<std::string>{"model", file, "--out", "out"}, {"run", file, "--out", "out"},
                                                {"figure", file, "--out", "out"}, {"bench", file}}) {
      const Result r = dynlab(dir, args);
      INFO(args[0], " ", file, "\nstderr: ", r.err);
      CHECK(r.code == 2);
      CHECK(r.err.rfind("error: ", 0) == 0);
      CHECK(lines(r.err) == 1);
      CHECK_FALSE(hasControl(r.err));
      CHECK_FALSE(hasControl(r.out));
    }
    // Also a file that does not exist.
    const Result r = dynlab(dir, {"model", "missing" + file});
    INFO(r.err);
    CHECK(r.code == 2);
    CHECK(lines(r.err) == 1);
    CHECK_FALSE(hasControl(r.err));
  }
}

TEST_CASE("dynlab new-lab: a name with a newline or an ESC gets one escaped line") {
  const TempDir dir("names_new_lab");
  fs::create_directories(dir / "labs");
  for (const std::string& name : {std::string("a\nb"), std::string("a\x1b[2Jb"), std::string("lab\xe2\x80\xae")}) {
    const Result r = dynlab(dir, {"new-lab", name, "--from", "fivebar", "--labs", (dir / "labs").string()});
    INFO(r.err);
    CHECK(r.code == 2);
    CHECK(lines(r.err) == 1);
    CHECK_FALSE(hasControl(r.err));
    CHECK(fs::is_empty(dir / "labs"));
  }
}

TEST_CASE("bound messages print the refused value with the digits that show why it is out of range") {
  const TempDir dir("names_bounds");
  // A time budget: the grader's own check and text (dynlab.grade gives the same).
  writeFile(dir / "sub.json", R"({"lab": "slider_crank", "gains": {}})");
  for (const auto& [given, shown] : {std::pair{"0", "got 0"}, {"86400.00000000001", "got 86400.00000000001"}, {"-1", "got -1"}}) {
    const Result r = dynlab(dir, {"grade", "sub.json", "--time-budget", given});
    INFO(r.err);
    CHECK(r.code == 2);
    CHECK(r.err.find("--time-budget: expected a time budget in [1, 86400] s, " + std::string(shown)) != std::string::npos);
  }
  // A model file's duration.
  const Result r = dynlab(dir, {"run", std::string(DYNLAB_SOURCE_DIR) + "/assets/models/fourbar.xml", "--duration", "600.0000000000001"});
  INFO(r.err);
  CHECK(r.code == 2);
  CHECK(r.err.find("got 600.0000000000001") != std::string::npos);
}
