// dynlab handout LAB: the student handout, for any lab through the lab interface. The prose a person
// writes (labs/<name>/handout.md: ## Mechanism, ## Exercise, ## Hints) is stitched around sections
// generated from the lab's JSON at run time — gains, submission, metrics, scenarios, tests,
// watchdog, leaderboard — so every number in the handout is the grader's own.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <map>
#include <sstream>

#include "app/cli/course/course.h"
#include "app/cli/output.h"
#include "grading/metric_doc.h"
#include "grading/report.h"
#include "grading/rubric.h"
#include "grading/student.h"
#include "labs/run.h"
#include "labs/submission.h"

namespace fs = std::filesystem;

namespace dyn::app {
namespace {

std::string num(double x) { return fmtConfigNumber(x); }
std::string code(const std::string& s) { return "`" + s + "`"; }
// A unit after a number ("0.003 m"); dimensionless ("1") and unknown units print nothing.
std::string withUnit(double x, const std::string& unit) {
  return num(x) + (unit.empty() || unit == "1" ? "" : (unit == "°" ? unit : " " + unit));
}
// Table cells may not hold a bare '|'.
std::string cell(std::string s) {
  for (std::size_t at = 0; (at = s.find('|', at)) != std::string::npos; at += 2) s.replace(at, 1, "\\|");
  return s;
}

// The person-written prose, cut at its "## " headings; {/pointer}s filled from the config.
struct Prose {
  std::map<std::string, std::string> sections;  // heading → body
  std::vector<std::string> order;
};

Prose readProse(const fs::path& file, const JsonView& config) {
  std::error_code ec;
  if (!fs::exists(file, ec)) throw InputError(file.string(), "/", "expected the lab's handout prose (## Mechanism, ## Exercise, ## Hints)");
  // A lab folder is input too: a regular file of valid UTF-8 (a FIFO there is refused, never waited on).
  std::string text = readTextFile(file.string(), 1u << 20);
  // Comments are notes to the author, not to the student.
  for (std::size_t a; (a = text.find("<!--")) != std::string::npos;) {
    const std::size_t b = text.find("-->", a);
    text.erase(a, b == std::string::npos ? std::string::npos : b + 3 - a);
  }
  Prose p;
  std::istringstream lines(text);
  std::string line, heading;
  while (std::getline(lines, line)) {
    if (line.rfind("## ", 0) == 0) {
      heading = line.substr(3);
      p.order.push_back(heading);
      continue;
    }
    if (!heading.empty()) p.sections[heading] += line + "\n";
  }
  for (const char* need : {"Mechanism", "Exercise"})
    if (!p.sections.count(need)) throw InputError(file.string(), "/", std::string("expected a section \"## ") + need + "\"");
  for (auto& [h, body] : p.sections) body = fillFromConfig(body, JsonView(config.raw(), file.string()), "## " + h);
  return p;
}

// "/controller/delay = 0.03 (was 0.01)" for every value a scenario's merge patch sets.
void describePatch(const json& patch, const json& base, const std::string& at, std::vector<std::string>& out) {
  for (const auto& [k, v] : patch.items()) {
    const std::string path = at + "/" + k;
    const json::json_pointer ptr(path);
    const bool had = base.contains(ptr);
    if (v.is_object() && had && base.at(ptr).is_object()) {
      describePatch(v, base, path, out);
      continue;
    }
    auto show = [](const json& j) { return j.is_number() ? num(j.get<double>()) : j.dump(); };
    out.push_back(code(path) + " = " + show(v) + (had ? " (was " + show(base.at(ptr)) + ")" : " (not set in the lab)"));
  }
}

std::string join(const std::vector<std::string>& parts, const std::string& sep) {
  std::string s;
  for (const auto& p : parts) s += (s.empty() ? "" : sep) + p;
  return s;
}

struct Handout {
  std::string lab, config_file;
  json config;  // on the student's plant
  const LabEntry* entry;
  Rubric rubric;
  PlantChoice student;              // whose handout (nominal: everyone's)
  std::vector<PlantValue> varied;  // the varied parameters (labs/variants.h) at this handout's plant's values

  // The lab built with a scenario's patch: its loops name the screening metrics.
  std::vector<LinearLoop> loops(const Scenario& s) const {
    return buildLab(*entry, mergePatch(config, s.patch), config_file)->linearise();
  }
  MetricDoc doc(const std::string& metric, const Scenario& s) const {
    const json patched = mergePatch(config, s.patch);
    const auto docs = parseMetricDocs(JsonView(patched, config_file));
    if (auto it = docs.find(metric); it != docs.end()) return it->second;
    if (auto d = screeningMetricDoc(metric, loops(s))) return *d;
    throw InputError(config_file, "/metric_docs", "expected a definition of metric \"" + metric + "\" (the rubric uses it)");
  }

  std::string gains() const {
    std::string md = "## Your gains\n\nThe gains you submit. Each must lie within its bounds; the default is what the "
                     "lab starts from.\n\n| gain | default | min | max | unit | what it does |\n|---|---|---|---|---|---|\n";
    for (const auto& [name, g] : config.at("gains").items()) {
      const std::string unit = g.value("unit", "");
      md += "| " + code(name) + " | " + num(g.at("value")) + " | " + num(g.at("min")) + " | " + num(g.at("max")) + " | " +
            cell(unit == "1" ? "1 (dimensionless)" : unit) + " | " + cell(g.value("doc", "")) + " |\n";
    }
    return md + "\n";
  }

  // The plant per student (labs/variants.h): the ranges, and on a student's handout their values and key.
  std::string plant() const {
    if (varied.empty()) return {};
    std::string md = "## Your plant\n\n";
    md += student.nominal()
              ? "Each student's plant differs in the parameters below, drawn from these ranges by the student's key; you are "
                "graded on yours. Your own handout, which the course staff make for you with your student ID, shows your "
                "values and your key.\n\n| parameter | nominal | range | unit | what it is |\n|---|---|---|---|---|\n"
              : "This is the handout of student " + code(student.student) + ": every number in it is of your plant, and you "
                "are graded on it. Your plant's varied parameters:\n\n| parameter | yours | range | unit | what it is |\n"
                "|---|---|---|---|---|\n";
    for (const PlantValue& v : varied)
      md += "| " + cell(v.parameter.name) + " | " + num(v.value) + " | " + num(v.parameter.min) + " … " +
            num(v.parameter.max) + " | " + cell(v.parameter.unit) + " | " + cell(v.parameter.doc) + " |\n";
    if (student.nominal()) return md + "\n";
    md += "\nYour key is " + code(student.key) + ". To run, tune and grade on your plant, set `DYNLAB_STUDENT_KEY=" +
          student.key + "` and add `--student " + student.student + "` to `dynlab run`, `ui`, `figure` and `grade` "
          "(Python: `dynlab.Lab(\"" + lab + "\", student=\"" + student.student + "\")`). Gains tuned on another "
          "student's plant are graded on yours.\n\n";
    return md;
  }

  std::string submission() const {
    std::string md = "## What you submit\n\nOne JSON file: the lab's name, every gain, and the options below (an option "
                     "left out keeps the lab's default). Nothing else is accepted. Starting point (the defaults):\n\n```json\n";
    json example = {{"lab", lab}, {"gains", json::object()}};
    for (const auto& [name, g] : config.at("gains").items()) example["gains"][name] = g.at("value");
    const json options = config.value("submission_options", json::object());
    for (const auto& [key, o] : options.items()) example[key] = config.at(json::json_pointer(o.at("target").get<std::string>()));
    md += example.dump() + "\n```\n\n";
    if (!options.empty()) {
      md += "| option | choices | default | what it selects |\n|---|---|---|---|\n";
      for (const auto& [key, o] : options.items()) {
        std::vector<std::string> choices;
        for (const auto& c : o.at("choices")) choices.push_back(code(c.get<std::string>()));
        md += "| " + code(key) + " | " + join(choices, ", ") + " | " +
              code(config.at(json::json_pointer(o.at("target").get<std::string>())).get<std::string>()) + " | " +
              cell(o.value("doc", "")) + " |\n";
      }
      md += "\n";
    }
    md += "The handout's written questions go in the same file, as text for the course staff (never graded): "
          "`\"answers\": {\"q1\": \"…\", \"q2\": \"…\"}` (at most " + std::to_string(kMaxAnswers) + " answers of at most " +
          std::to_string(kMaxAnswerBytes) + " bytes each).\n\n";
    md += "The exact format, as a JSON Schema (`dynlab schema " + lab + "` prints it):\n\n```json\n" +
          submissionSchema(config, lab).dump(2) + "\n```\n\n";
    return md;
  }

  std::string metrics() const {
    // Every metric the rubric or the leaderboard reads, defined as the grader computes it.
    std::vector<std::string> used;
    auto add = [&](const std::string& m) {
      if (std::find(used.begin(), used.end(), m) == used.end()) used.push_back(m);
    };
    for (const auto& t : rubric.tests) add(t.metric);
    for (const auto& l : rubric.leaderboard) add(l.metric);
    const Scenario& nominal = rubric.scenarios.front();
    std::string md = "### Metrics\n\n| metric | definition | unit | time window | if you fall short |\n|---|---|---|---|---|\n";
    for (const auto& m : used) {
      const MetricDoc d = doc(m, nominal);
      md += "| " + code(m) + " | " + cell(d.what) + " | " + cell(d.unit == "1" ? "1 (dimensionless)" : d.unit) + " | " +
            cell(d.window) + " | " + cell(adviceSummary(d.advice)) + " |\n";
    }
    return md + "\n";
  }

  std::string scenarios() const {
    std::string md = "### Scenarios\n\nEach scenario is the lab with a few values changed (after your gains are "
                     "applied); your gains are run once in each.\n\n| scenario | what it tests | what changes |\n|---|---|---|\n";
    for (const auto& s : rubric.scenarios) {
      std::vector<std::string> changes;
      describePatch(s.patch, config, "", changes);
      md += "| " + code(s.name) + " | " + cell(s.about) + " | " + (changes.empty() ? "nothing" : cell(join(changes, "; "))) + " |\n";
    }
    return md + "\n";
  }

  std::string tests() const {
    std::string md = "### Tests\n\nEach test reads one metric of one scenario. Between the two thresholds the credit "
                     "is linear: `fraction = clamp((zero − m) / (zero − full), 0, 1)`; a metric that does not exist "
                     "(the run was stopped) scores 0.\n\n";
    int i = 0;
    for (const auto& t : rubric.tests) {
      const Scenario& s = *rubric.scenario(t.scenario);
      const MetricDoc d = doc(t.metric, s);
      const bool lower = t.full < t.zero;  // smaller is better
      md += std::to_string(++i) + ". **" + t.name + "** (" + num(t.points) + (t.points == 1 ? " point" : " points") +
            ", scenario " + code(t.scenario) + ": " + s.about + "). Metric " + code(t.metric) + ": " + d.what + (d.unit.empty() || d.unit == "1" ? "" : ", in " + d.unit) +
            "; window: " + d.window + ". Full credit at " + code(t.metric) + (lower ? " ≤ " : " ≥ ") + withUnit(t.full, d.unit) +
            ", none at " + (lower ? "≥ " : "≤ ") + withUnit(t.zero, d.unit) + "." +
            (t.plot ? " Your report shows a plot of " + join(t.plot->columns, ", ") + "." : "") +
            (t.visibility != "visible" ? " (Shown to you " + t.visibility + ".)" : "") + "\n";
    }
    md += "\n| # | test | scenario | metric | full credit | zero credit | points |\n|---|---|---|---|---|---|---|\n";
    i = 0;
    for (const auto& t : rubric.tests) {
      const std::string unit = doc(t.metric, *rubric.scenario(t.scenario)).unit;
      md += "| " + std::to_string(++i) + " | " + cell(t.name) + " | " + code(t.scenario) + " | " + code(t.metric) + " | " +
            withUnit(t.full, unit) + " | " + withUnit(t.zero, unit) + " | " + num(t.points) + " |\n";
    }
    md += "| | **total** | | | | | **" + num(rubric.maxScore()) + "** |\n\n";
    return md;
  }

  // The lecture's points the grade is built to make: each lesson pair, as the rubric states it.
  std::string lessons() const {
    if (rubric.lessons.empty()) return "";
    std::string md = "### What the grade teaches\n\nThe rubric is checked against the lecture: of each pair of "
                     "designs below, both tuned with care, the first must score ahead of the second by at least the "
                     "share shown (`dynlab lessons " + lab + "` grades the pairs shipped in the lab's folder).\n\n";
    for (const auto& l : rubric.lessons)
      md += "* " + code(fs::path(l.better).stem().string()) + " ahead of " + code(fs::path(l.worse).stem().string()) +
            " by ≥ " + num(l.margin * 100) + " % of the points: " + l.about + "\n";
    return md + "\n";
  }

  std::string watchdog() const {
    const Watchdog& w = rubric.watchdog;
    std::string md = "### The watchdog\n\nA run that goes bad is stopped, and its tests score 0: any value becomes "
                     "non-finite, the run exceeds " + num(double(w.max_steps)) + " steps, or one of these leaves its range:\n\n";
    for (const auto& l : w.limits)
      md += "* " + l.what + " (" + code(l.column) + "): " + (std::isfinite(l.min) ? num(l.min) : "−∞") + " … " +
            (std::isfinite(l.max) ? num(l.max) : "∞") + "\n";
    return md + "\n";
  }

  std::string leaderboard() const {
    if (rubric.leaderboard.empty()) return "";
    std::string md = "### Leaderboard\n\nNot graded; ranked on Gradescope.\n\n| entry | scenario | metric | scale | better |\n"
                     "|---|---|---|---|---|\n";
    for (const auto& l : rubric.leaderboard)
      md += "| " + cell(l.name) + " | " + code(l.scenario) + " | " + code(l.metric) + " | × " + num(l.scale) + " | " +
            (l.order == "asc" ? "lower" : "higher") + " |\n";
    return md + "\n";
  }

  // Columns worth plotting first: the first test plot's response and reference (the lab's own names).
  std::string plotColumns() const {
    for (const auto& t : rubric.tests) {
      if (!t.plot || t.plot->columns.empty() || !t.plot->x.empty()) continue;
      return t.plot->columns.front() + (t.plot->reference.empty() ? "" : "," + t.plot->reference);
    }
    const std::vector<std::string> columns = buildLab(*entry, config, config_file)->columns();
    return columns.size() > 1 ? columns[1] : "t";
  }

  // A map over the first two gains' whole ranges, 9 points each, that can share a map (the options
  // the map sets for each, "map"/"gain_options", agree): a command that runs as printed.
  std::string mapAxes() const {
    const json& gains = config.at("gains");
    const json options = config.contains("map") ? config["map"].value("gain_options", json::object()) : json::object();
    const auto agree = [&](const std::string& a, const std::string& b) {
      if (!options.contains(a) || !options.contains(b)) return true;
      for (const auto& [key, choice] : options[a].items())
        if (options[b].contains(key) && options[b][key] != choice) return false;
      return true;
    };
    const auto axis = [&](const std::string& flag, const std::string& name) {
      return flag + name + "=" + num(gains.at(name).at("min")) + ":" + num(gains.at(name).at("max")) + ":9";
    };
    for (auto a = gains.begin(); a != gains.end(); ++a)
      for (auto b = std::next(a); b != gains.end(); ++b)
        if (agree(a.key(), b.key())) return axis(" --x ", a.key()) + axis(" --y ", b.key());
    return " --x GAIN=from:to:9 --y GAIN=from:to:9";
  }

  std::string howTo() const {
    const std::string L = lab;
    return "## Run, tune, self-grade\n\n"
           "Write your submission, e.g. `my_gains.json`, as above; then:\n\n"
           "| to | run |\n|---|---|\n"
           "| simulate it (traces, summary, video) | `dynlab run " + L + " --gains my_gains.json --video` |\n"
           "| tune it in a window (sliders, live plots, screening) and save it | `dynlab ui " + L + " --gains my_gains.json` |\n"
           "| grade it exactly as the autograder will | `dynlab grade my_gains.json --lab " + L + "` |\n"
           "| plot any trace column | `dynlab figure " + L + " --gains my_gains.json --plot " + plotColumns() + "` |\n"
           "| see where gains are stable (any two gains, NAME=from:to:points) | `dynlab map " + L + mapAxes() + " --sim` |\n"
           "| check the format | `dynlab schema " + L + "` |\n\n"
           "`dynlab grade` writes `out/grade/report.html` with every test, its plot and the screening notes: the score it "
           "prints is the score you will get (the grader is deterministic).\n\n";
  }

  std::string markdown(const Prose& prose) const {
    std::string md = "# " + config.value("title", lab) + "\n\n*Student handout for the dynlab lab " + code(lab) +
                     ". Generated by `dynlab handout " + lab + "` from the lab's JSON and its prose: every gain, bound, "
                     "metric, threshold and point below is the grader's own. For a PDF, open `handout.html` in a browser and "
                     "print it (Save as PDF).*\n\n" + config.value("description", "") + "\n\n";
    md += "## The mechanism\n\n" + prose.sections.at("Mechanism") + "\n";
    md += "## The exercise\n\n" + prose.sections.at("Exercise") + "\n";
    md += plant() + gains() + submission();
    md += "## How you are graded\n\nThe grader runs your gains on the hand-written engine in each scenario below "
          "(dt = " + num(config.at("simulation").at("dt")) + " s, " + num(config.at("simulation").at("duration")) +
          " s per run) and screens them on the linearised loops first. " + num(rubric.maxScore()) + " points in all.\n\n";
    md += metrics() + scenarios() + tests() + lessons() + watchdog() + leaderboard() + howTo();
    // Any further sections the author wrote (hints first), in their order.
    for (const auto& h : prose.order)
      if (h != "Mechanism" && h != "Exercise") md += "## " + h + "\n\n" + prose.sections.at(h) + "\n";
    return md;
  }
};

// A standalone page: the report's Markdown-to-HTML (cmark-gfm, safe mode, the style inline, nothing
// fetched), with room for code blocks and print.
std::string html(const std::string& markdown, const std::string& title) {
  return renderHtml(markdown, title, "td,th{vertical-align:top}pre{background:#f6f6f6;padding:.6em;overflow-x:auto}"
                                     "@media print{pre{white-space:pre-wrap}}");
}

}  // namespace

HandoutText handoutText(const HandoutArgs& a) {
  const PlantChoice student = studentPlant(a.student);
  LoadedLab loaded = loadLab(a.lab, a.config, "", std::nullopt, student);
  // The config's own values of the varied parameters: the nominal ones, or this student's.
  Handout h{a.lab, loaded.config_file, loaded.config, loaded.entry, parseRubric(JsonView(loaded.config, loaded.config_file)),
            student, drawPlant(JsonView(loaded.config, loaded.config_file), PlantChoice{}, a.lab)};
  const Prose prose = readProse(fs::path(labFolder(a.lab)) / "handout.md", JsonView(loaded.config, loaded.config_file));
  return {h.markdown(prose), loaded.config.value("title", a.lab)};
}

int handout(const HandoutArgs& a) {
  std::string md, page;
  std::vector<std::string> formats;
  try {
    // Formats first: a request we cannot serve writes nothing.
    std::stringstream fs_list(a.format);
    for (std::string f; std::getline(fs_list, f, ',');) {
      if (f == "pdf")
        throw InputError("<command line>", "--format", "pdf is not written by dynlab (no small Debian converter keeps "
                         "the handout's symbols); write html and print it to PDF from a browser (Save as PDF)");
      if (f != "md" && f != "html") throw InputError("<command line>", "--format", "expected md, html or pdf, got \"" + f + "\"");
      formats.push_back(f);
    }
    if (formats.empty()) throw InputError("<command line>", "--format", "expected at least one of md, html");
    const HandoutText text = handoutText(a);
    md = text.markdown;
    page = html(md, text.title + " — handout");
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  // Everything is generated; now the output folder, staged so a failure leaves nothing half-written.
  const fs::path out = a.out.empty() ? fs::path("out") / a.lab / "handout" : fs::path(a.out);
  std::error_code ec;
  if (fs::exists(out, ec) && !fs::is_directory(out, ec)) {
    std::fprintf(stderr, "error: --out %s: expected a directory, found a file\n", out.c_str());
    return 2;
  }
  std::optional<Staging> staging;
  try {
    staging.emplace(out);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: --out %s: cannot create the output directory (%s)\n", out.c_str(),
                 e.what());
    return 2;
  }
  try {
    staging->owns({"handout.md", "handout.html"});
    for (const auto& f : formats) staging->write("handout." + f, f == "md" ? md : page);
    staging->commit();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  for (const auto& f : formats) std::printf("%s\n", (out / ("handout." + f)).c_str());
  return 0;
}

}  // namespace dyn::app
