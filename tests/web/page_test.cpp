// The page in a real browser (issue 42 items 3, 5, 7): build/web/index.html served locally and opened
// in Debian's headless Chromium (SwiftShader WebGL 2) by tests/web/page_check.js (node: a static
// server and the DevTools protocol on a pipe). For every lab — the six with C++ code and the three
// model-file labs, whose models the page reads from the descriptions scripts/web packs into dynlab.data —
// the canvas is not blank (the page counts, inside its frame, the scene's pixels that differ from the
// background), and every shipped example opened as ?lab=LAB&gains=<the file's JSON>&grade=1 prints one
// console line "dynlab results.json: {...}" equal to the native `dynlab grade`'s results.json but
// execution_time.
// Skipped (DYNLAB_TEST_SKIPPED) without node, Chromium or a current build/web (scripts/web); a failure
// instead under DYNLAB_REQUIRE_WEB=1 (CI, tests/web/web_required.h).
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>
#include <cctype>
#include <cstdio>
#include <iostream>
#include <map>
#include <sstream>

#include "tests/app/cli_run.h"
#include "tests/app/lab_examples.h"
#include "tests/web/web_required.h"

using namespace dyn::test::cli;
using dyn::test::labExamples;
using nlohmann::json;

namespace {

const fs::path kSite = fs::path(DYNLAB_SOURCE_DIR) / "build" / "web";
const fs::path kCheck = fs::path(DYNLAB_SOURCE_DIR) / "tests" / "web" / "page_check.js";
const char* const kLabs[] = {"slider_crank", "pen_on_table", "unicycle",    "grasp",         "impedance",
                             "motion_control", "fivebar",   "puma_motion", "puma_impedance"};

std::string chromium() {
  for (const char* name : {"chromium", "chromium-browser"})
    if (onPath(name)) return name;
  return "";
}

// Why the page cannot be checked here ("" when it can): no browser, no node, or a site older than a
// source it is built from.
std::string missing() {
  if (!onPath("node")) return "node is not installed (package nodejs)";
  if (chromium().empty()) return "no Chromium (apt-get install --no-install-recommends chromium)";
  for (const char* f : {"index.html", "dynlab.js", "dynlab.wasm", "dynlab.data"})
    if (!fs::exists(kSite / f)) return (kSite / f).string() + " is not built (run scripts/web)";
  const auto built = fs::last_write_time(kSite / "dynlab.wasm");
  for (const char* dir : {"physics", "labs", "grading", "render", "app/web", "app/ui"})
    for (const auto& e : fs::recursive_directory_iterator(fs::path(DYNLAB_SOURCE_DIR) / dir)) {
      const std::string ext = e.path().extension().string();
      if (e.is_regular_file() && (ext == ".cpp" || ext == ".h" || ext == ".json") && e.last_write_time() > built)
        return e.path().string() + " changed after build/web was built (run scripts/web)";
    }
  return "";
}

bool skipped() { return dyn::test::webTestCannotRun(missing(), "the page was not checked"); }

// Opens each query in the browser; what each page said, by query.
std::map<std::string, json> openPages(const TempDir& dir, const std::vector<std::string>& queries) {
  std::vector<std::string> argv = {"node", kCheck.string(), kSite.string(), chromium(), "120"};
  argv.insert(argv.end(), queries.begin(), queries.end());
  ProcessOptions o;
  o.timeout_s = 120.0 * double(queries.size()) + 60;
  const Result r = run(dir, argv, o);
  CAPTURE(r.err);
  REQUIRE(r.code == 0);
  std::map<std::string, json> pages;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) {
    const json page = json::parse(line);
    pages[page.at("query").get<std::string>()] = page;
  }
  return pages;
}

// The line of a page's console that starts with prefix (its rest), or "".
std::string lineAfter(const json& page, const std::string& prefix) {
  for (const auto& l : page.at("lines"))
    if (l.get<std::string>().rfind(prefix, 0) == 0) return l.get<std::string>().substr(prefix.size());
  return "";
}

std::string percentEncoded(const std::string& s) {
  std::string out;
  for (unsigned char c : s) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~') out += char(c);
    else {
      char hex[4];
      std::snprintf(hex, sizeof hex, "%%%02X", c);
      out += hex;
    }
  }
  return out;
}

json withoutTime(json results) {
  results.erase("execution_time");
  return results;
}

}  // namespace

TEST_CASE("the page draws every lab's mechanism in WebGL 2, the model-file labs' too") {
  if (skipped()) return;
  TempDir dir("web_page_canvas");
  std::vector<std::string> queries;
  for (const char* lab : kLabs) queries.push_back(std::string("?lab=") + lab + "&probe=1");
  const auto pages = openPages(dir, queries);
  for (const char* lab : kLabs) {
    CAPTURE(lab);
    const json& page = pages.at(std::string("?lab=") + lab + "&probe=1");
    CAPTURE(page.dump());
    CHECK(page.at("exceptions").empty());
    CHECK(page.at("done").get<bool>());
    CHECK(lineAfter(page, "dynlab page: ").empty());  // the lab opened (a model-file lab: its description read)
    // "LAB N of M scene pixels drawn (WxH canvas)": a blank canvas draws none.
    long drawn = 0, area = 0;
    const std::string probe = lineAfter(page, "dynlab canvas: ");
    char name[64] = {};
    REQUIRE(std::sscanf(probe.c_str(), "%63s %ld of %ld", name, &drawn, &area) == 3);
    CHECK(std::string(name) == lab);
    CHECK(area > 0);
    CHECK(drawn > area / 50);  // the mechanism, its floor and the overlay: far more than 2 % of the view
  }
}

TEST_CASE("?lab=&gains=&grade=1 prints the native grade of every lab's examples") {
  if (skipped()) return;
  TempDir dir("web_page_grade");
  std::vector<std::pair<std::string, fs::path>> cases;
  std::vector<std::string> queries;
  for (const char* lab : kLabs)
    for (const fs::path& ex : labExamples(lab)) {
      cases.emplace_back(lab, ex);
      queries.push_back(std::string("?lab=") + lab + "&gains=" + percentEncoded(readFile(ex)) + "&grade=1");
    }
  const auto pages = openPages(dir, queries);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const auto& [lab, ex] = cases[i];
    CAPTURE(ex);
    const std::string out = (dir / (lab + "_" + ex.stem().string())).string();
    (void)dynlab(dir, {"grade", ex.string(), "--lab", lab, "--no-plots", "--out", out});
    REQUIRE(fs::exists(fs::path(out) / "results.json"));
    const json& page = pages.at(queries[i]);
    CHECK(page.at("exceptions").empty());
    const std::string line = lineAfter(page, "dynlab results.json: ");
    REQUIRE_MESSAGE(!line.empty(), page.dump());
    const json native = withoutTime(json::parse(readFile(fs::path(out) / "results.json")));
    const json web = withoutTime(json::parse(line));
    CHECK(native.at("score") == web.at("score"));
    CHECK(native == web);
  }
}
