// dynlab handout end to end: for every registered lab the handout names every gain, rubric test,
// scenario and metric with the JSON's own numbers (a changed threshold, bound or window in a
// --config shows up changed); every `dynlab ...` command it prints runs as printed (a student
// copies them); the HTML is self-contained; bad input is one line and exit 2.
#include <doctest/doctest.h>

#include <cmath>

#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>

#include "tests/app/cli_run.h"

using namespace dyn::test::cli;
using nlohmann::json;

namespace {

// A JSON number as the handout prints it (integers plain, else 6 significant digits).
// A JSON number as a reader writes it: whole numbers in full (1000000, not 1e+06), others to 6 digits.
std::string num(double x) {
  char b[40];
  if (x == std::floor(x) && std::abs(x) < 1e15) std::snprintf(b, sizeof b, "%.0f", x);
  else std::snprintf(b, sizeof b, "%.6g", x);
  return b;
}

std::vector<std::string> labNames(const TempDir& dir) {
  const Result r = dynlab(dir, {"list"});
  REQUIRE(r.code == 0);
  std::vector<std::string> names;
  std::istringstream in(r.out);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) names.push_back(line.substr(0, line.find(' ')));
  REQUIRE_FALSE(names.empty());
  return names;
}

bool has(const std::string& text, const std::string& what) { return text.find(what) != std::string::npos; }

// A command line split into words as a POSIX shell splits one with no expansions in it: at spaces,
// a '...' or "..." part kept whole without its quotes.
std::vector<std::string> shellWords(const std::string& command) {
  std::vector<std::string> words;
  std::string word;
  bool in_word = false;
  char quote = 0;
  for (const char c : command) {
    if (quote) {
      if (c == quote) quote = 0;
      else word += c;
    } else if (c == ' ' || c == '\t' || c == '\n') {
      if (in_word) words.push_back(word);
      word.clear();
      in_word = false;
    } else {
      in_word = true;
      if (c == '\'' || c == '"') quote = c;
      else word += c;
    }
  }
  if (in_word) words.push_back(word);
  return words;
}

// The handout's example submission: its first ```json block.
std::string exampleSubmission(const std::string& md) {
  const std::size_t at = md.find("```json\n");
  REQUIRE(at != std::string::npos);
  return md.substr(at + 8, md.find("```", at + 8) - at - 8);
}

// What a test adds to a printed command so it stays quick and writes where the test looks: a short
// run, no video or plots where the option exists, its own --out. The command itself is as printed.
std::vector<std::string> quickened(const std::string& sub, int k) {
  const std::vector<std::string> out = {"--out", "o" + std::to_string(k)};
  if (sub == "run") return cat({"--duration", "0.4"}, out);
  if (sub == "figure") return cat({"--duration", "0.4", "--engine", "hand", "--format", "svg"}, out);
  if (sub == "map") return {"--duration", "0.2", "--out", "m" + std::to_string(k) + ".png"};
  if (sub == "grade" || sub == "compare") return cat({"--no-plots"}, out);
  if (sub == "handout") return out;
  if (sub == "ui") return {"--frames", "2"};
  return {};
}

}  // namespace

TEST_CASE("every lab's handout names every gain, test, scenario and metric with the JSON's numbers") {
  TempDir dir("handout_every");
  for (const auto& lab : labNames(dir)) {
    INFO("lab ", lab);
    const Result r = dynlab(dir, {"handout", lab, "--out", "h_" + lab});
    REQUIRE_MESSAGE(r.code == 0, r.err);
    const std::string md = readFile(dir / ("h_" + lab + "/handout.md"));
    const std::string html = readFile(dir / ("h_" + lab + "/handout.html"));
    CHECK(has(md, "For a PDF, open `handout.html` in a browser and print it (Save as PDF)."));  // dynlab writes none
    const json config = json::parse(readFile(fs::path(DYNLAB_SOURCE_DIR) / "labs" / lab / (lab + ".json")));
    for (const auto& [gain, g] : config.at("gains").items()) {
      INFO("gain ", gain);
      CHECK(has(md, "| `" + gain + "` | " + num(g.at("value")) + " | " + num(g.at("min")) + " | " + num(g.at("max")) + " |"));
      CHECK(has(html, "<code>" + gain + "</code>"));
    }
    for (const auto& [name, _] : config.at("rubric").at("scenarios").items()) CHECK_MESSAGE(has(md, "`" + name + "`"), name);
    for (const auto& t : config.at("rubric").at("tests")) {
      const std::string name = t.at("name"), metric = t.at("metric");
      INFO("test ", name);
      CHECK(has(md, "**" + name + "**"));
      // Its row: scenario, metric, both thresholds, points.
      const std::size_t row = md.find("| " + name + " | `" + t.at("scenario").get<std::string>() + "` | `" + metric + "` | ");
      REQUIRE(row != std::string::npos);
      const std::string line = md.substr(row, md.find('\n', row) - row);
      CHECK(has(line, "| " + num(t.at("full"))));
      CHECK(has(line, "| " + num(t.at("zero"))));
      CHECK(has(line, "| " + num(t.at("points")) + " |"));
      // The metric is defined in the metrics table, with a unit and a window.
      CHECK(has(md, "| `" + metric + "` | "));
    }
    for (const auto& l : config.at("rubric").value("leaderboard", json::array())) CHECK(has(md, l.at("name").get<std::string>()));
    for (const std::string& how : {"dynlab run " + lab, "dynlab ui " + lab, "dynlab grade my_gains.json --lab " + lab, "dynlab schema " + lab})
      CHECK_MESSAGE(has(md, how), how);
  }
}

TEST_CASE("every dynlab command a handout prints runs as printed, in every lab") {
  TempDir dir("handout_commands");
  for (const auto& lab : labNames(dir)) {
    INFO("lab ", lab);
    const TempDir student("handout_commands_" + lab);  // one folder per lab: its own my_gains.json
    REQUIRE(dynlab(dir, {"handout", lab, "--out", "h_" + lab, "--format", "md"}).code == 0);
    const std::string md = readFile(dir / ("h_" + lab + "/handout.md"));
    const std::string example = exampleSubmission(md);
    // Every code span that is a dynlab command, once.
    std::set<std::string> commands;
    const std::regex span("`(dynlab [^`]+)`");
    for (auto it = std::sregex_iterator(md.begin(), md.end(), span); it != std::sregex_iterator(); ++it) commands.insert((*it)[1]);
    REQUIRE(commands.size() >= 8);
    int k = 0, ran = 0;
    for (const auto& command : commands) {
      INFO("command: ", command);
      // The words a student's shell makes of it: nothing in it is expanded, quotes group words.
      CHECK_MESSAGE(command.find_first_of("$`\\|&;<>()*?[]{}~!") == std::string::npos, "a shell would expand part of it");
      const std::vector<std::string> words = shellWords(command);
      // "`dynlab grade`" in a sentence names a command; a command has its argument.
      if (words.size() < 3 || words[2][0] == '-') continue;
      const std::string sub = words[1];
      std::vector<std::string> args = {sub};
      for (std::string word : std::vector<std::string>(words.begin() + 2, words.end())) {
        // A file it names: the repository's (labs/...: run from its root), else the student's submission.
        if (word.size() > 5 && word.substr(word.size() - 5) == ".json") {
          if (fs::exists(fs::path(DYNLAB_SOURCE_DIR) / word)) {
            word = (fs::path(DYNLAB_SOURCE_DIR) / word).string();
          } else if (!fs::exists(student / word)) {
            fs::create_directories((student / word).parent_path());
            writeFile(student / word, example);
          }
        }
        args.push_back(word);
      }
      args = cat(args, quickened(sub, ++k));
      ++ran;
      Result r;
      if (sub == "ui") {
        if (!haveXvfb()) {
          std::cout << "note: xvfb-run not found, `" << command << "` not run\n";
          continue;
        }
        r = run(student, inXvfb(cat({DYNLAB_BIN}, args), "1600x900"));
      } else {
        r = dynlab(student, args);
      }
      INFO("ran: dynlab ", shown(args), "\nstdout: ", r.out, "\nstderr: ", r.err);
      // 0, or 1 for a run the watchdog stopped (the defaults of some labs are meant to fail a scenario).
      CHECK((r.code == 0 || (r.code == 1 && (sub == "run" || sub == "figure"))));
    }
    CHECK(ran >= 8);  // run, ui, grade, figure, map, schema, lessons, handout
  }
}

TEST_CASE("the handout follows the config: a changed threshold, bound and window show up changed") {
  TempDir dir("handout_config");
  json config = json::parse(defaultConfigText());
  config["rubric"]["tests"][0]["full"] = 0.0021;  // between the shipped full and zero (tracking, m)
  config["rubric"]["tests"][1]["points"] = 7;
  config["gains"]["kp_x"]["max"] = 12345;
  config["metrics"]["settle_time"] = 0.75;
  writeFile(dir / "changed.json", config.dump());
  REQUIRE(dynlab(dir, {"handout", "slider_crank", "--out", "a"}).code == 0);
  const Result r = dynlab(dir, {"handout", "slider_crank", "--config", "changed.json", "--out", "b", "--format", "md"});
  REQUIRE_MESSAGE(r.code == 0, r.err);
  const std::string before = readFile(dir / "a/handout.md"), after = readFile(dir / "b/handout.md");
  CHECK_FALSE(has(before, "0.0021"));
  CHECK(has(after, "≤ 0.0021 m"));
  CHECK(has(after, "| `kp_x` | 150 | 0 | 12345 |"));
  CHECK(has(before, "from t = 0.5 s on"));
  CHECK(has(after, "from t = 0.75 s on"));
  CHECK_FALSE(has(after, "from t = 0.5 s on"));
  CHECK(has(after, "(7 points, scenario `nominal`"));
  CHECK(has(after, "**" + num(15 - 3 + 7) + "**"));  // the total follows
  CHECK_FALSE(fs::exists(dir / "b/handout.html"));  // only the format asked for
  // The same inputs give the same bytes.
  REQUIRE(dynlab(dir, {"handout", "slider_crank", "--out", "c"}).code == 0);
  CHECK(readFile(dir / "c/handout.md") == before);
  CHECK(readFile(dir / "c/handout.html") == readFile(dir / "a/handout.html"));
}

TEST_CASE("the HTML handout is self-contained: no external reference of any kind") {
  TempDir dir("handout_html");
  REQUIRE(dynlab(dir, {"handout", "slider_crank", "--out", "h", "--format", "html"}).code == 0);
  const std::string html = readFile(dir / "h/handout.html");
  CHECK(html.rfind("<!doctype html>", 0) == 0);
  CHECK(has(html, "<table>"));
  for (const char* ref : {"src=", "<link", "@import", "url(", "href=\"http", "href=\"//", "<script", "<iframe"})
    CHECK_MESSAGE(!has(html, ref), "external reference: ", ref);
}

TEST_CASE("bad LAB, --out or --format: one line, exit 2, nothing written") {
  TempDir dir("handout_bad");
  checkBadInput(dir, {"handout", "no_such_lab", "--out", "h"}, {"no_such_lab"}, dir / "h");
  writeFile(dir / "a_file", "x");
  checkBadInput(dir, {"handout", "slider_crank", "--out", "a_file/h"}, {"a_file"}, dir / "a_file/h");
  checkBadInput(dir, {"handout", "slider_crank", "--out", "h", "--format", "pdf"}, {"pdf", "print it to PDF from a browser"},
                dir / "h");
  checkBadInput(dir, {"handout", "slider_crank", "--out", "h", "--format", "docx"}, {"docx"}, dir / "h");
  json config = json::parse(defaultConfigText());
  config["metric_docs"]["f_rms"]["window"] = "from t = {/metrics/no_such} s on";
  writeFile(dir / "bad.json", config.dump());
  checkBadInput(dir, {"handout", "slider_crank", "--config", "bad.json", "--out", "h"},
                {"bad.json", "/metric_docs/f_rms/window", "/metrics/no_such"}, dir / "h");
}
