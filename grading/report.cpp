// Results, terminal, Markdown and HTML forms of a grade; plots of each test's response.
#include "grading/report.h"

#include <cmark-gfm-core-extensions.h>
#include <cmark-gfm.h>

#include <filesystem>

#include "grading/escape.h"
#include "grading/grade.h"
#include "grading/plot.h"

namespace dyn {
namespace {

const ScenarioSummary& scenarioOf(const GradeReport& r, const std::string& name) {
  for (const auto& s : r.scenarios)
    if (s.scenario.name == name) return s;
  throw std::logic_error("no scenario " + name);
}

std::string points(double x) { return fmtNumber(std::round(x * 100) / 100); }

std::string slug(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (std::isalnum(static_cast<unsigned char>(c))) out += char(std::tolower(static_cast<unsigned char>(c)));
    else if (!out.empty() && out.back() != '-') out += '-';
  }
  while (!out.empty() && out.back() == '-') out.pop_back();
  return out.substr(0, 40);
}

// A metric's value with its unit, as feedback shows it ("0.01113 m"; dimensionless: the number). The
// number is plain digits; the unit (from the lab's JSON) is escaped for where it lands.
std::string withUnit(double x, const std::string& unit, std::string (*escape)(const std::string&)) {
  return fmtNumber(x) + (unit.empty() || unit == "1" ? "" : " " + escape(unit));
}
std::string mdUnit(double x, const std::string& unit) { return withUnit(x, unit, [](const std::string& u) { return mdText(u); }); }
std::string termUnit(double x, const std::string& unit) { return withUnit(x, unit, [](const std::string& u) { return termText(u); }); }

// The one-paragraph explanation of a test (Markdown), shared by results.json and report.md.
std::string testText(const GradeReport& r, const GradedTest& g) {
  const ScenarioSummary& sc = scenarioOf(r, g.test.scenario);
  std::string s = "Scenario **" + mdText(sc.scenario.name) + "** (" + mdText(sc.scenario.about) + "). ";
  if (std::isfinite(g.value)) {
    s += mdCode(g.test.metric) + " = **" + mdUnit(g.value, g.unit) + "**; full credit at " +
         mdUnit(g.test.full, g.unit) + ", zero at " + mdUnit(g.test.zero, g.unit) + ".";
  } else {
    s += "**No credit:** " + mdText(g.note) + ".";
  }
  if (!sc.failure.empty() && std::isfinite(g.value)) s += " (The run itself: " + mdText(sc.failure) + ".)";
  return s;
}

// A note with nothing to show is left out: an empty "- " item under a line would make it a heading.
bool blank(const std::string& s) { return s.find_first_not_of(" \t") == std::string::npos; }

std::string scenarioStatus(const ScenarioSummary& s) { return s.failure.empty() ? "completed" : s.failure; }

}  // namespace

double GradeReport::score() const {
  double s = 0;
  for (const auto& t : tests) s += t.score;
  return s;
}

double GradeReport::maxScore() const {
  double s = 0;
  for (const auto& t : tests) s += t.test.points;
  return s;
}

json resultsJson(const GradeReport& r) {
  json tests = json::array();
  for (std::size_t i = 0; i < r.tests.size(); ++i) {
    const GradedTest& g = r.tests[i];
    json extra = {{"scenario", g.test.scenario}, {"metric", g.test.metric}, {"full", g.test.full}, {"zero", g.test.zero}};
    extra["value"] = std::isfinite(g.value) ? json(g.value) : json(nullptr);
    if (!g.plot.empty()) extra["plot"] = g.plot;
    tests.push_back({{"name", g.test.name},
                     {"number", std::to_string(i + 1)},
                     {"score", g.score},
                     {"max_score", g.test.points},
                     {"status", g.score >= g.test.points - 1e-9 ? "passed" : "failed"},
                     {"output", testText(r, g)},
                     {"output_format", "md"},
                     {"tags", {g.test.scenario}},
                     {"visibility", g.test.visibility},
                     {"extra_data", extra}});
  }
  json scenarios = json::object();
  for (const auto& s : r.scenarios) {
    scenarios[s.scenario.name] = {{"about", s.scenario.about},
                                  {"status", scenarioStatus(s)},
                                  {"trace_hash", hashHexOf(s.trace_hash)},
                                  {"metrics", s.metrics},
                                  {"screening", s.screen_notes}};
    if (s.failure_time >= 0) scenarios[s.scenario.name]["failure_time"] = s.failure_time;
  }
  // The top of the page (Markdown): the score, and what the screening says about the gains.
  std::string output = "**dynlab " + mdText(r.lab) + ": " + points(r.score()) + " / " + points(r.maxScore()) + " points.**\n\n";
  for (const auto& s : r.scenarios) {
    if (s.scenario.name != "nominal") continue;
    for (const auto& n : s.screen_notes)
      if (!blank(n)) output += "- " + mdText(n) + "\n";
  }
  for (const auto& s : r.scenarios)
    if (!s.failure.empty()) output += "- Scenario **" + mdText(s.scenario.name) + "**: " + mdText(s.failure) + ".\n";
  json results = {{"score", r.score()},
                  {"output", output},
                  {"output_format", "md"},
                  {"test_output_format", "md"},
                  {"visibility", "visible"},
                  {"stdout_visibility", "hidden"},
                  {"tests", tests},
                  {"extra_data", {{"lab", r.lab}, {"fingerprint", r.fingerprint}, {"scenarios", scenarios}}}};
  if (!r.leaderboard.empty()) results["leaderboard"] = r.leaderboard;
  return jsonSanitized(results);  // names, notes and keys as valid UTF-8: dump() cannot throw
}

std::string terminalReport(const GradeReport& r) {
  std::string s = "Grading " + termText(r.submission) + " (" + termText(r.lab) + ")\n";
  for (const auto& g : r.tests) {
    s += "  " + points(g.score) + "/" + points(g.test.points) + "  " + termText(g.test.name) + " [" + termText(g.test.scenario) + "]: ";
    s += std::isfinite(g.value) ? termText(g.test.metric) + " = " + termUnit(g.value, g.unit) + " (full " +
                                      termUnit(g.test.full, g.unit) + ", zero " + termUnit(g.test.zero, g.unit) + ")"
                                : termText(g.note);
    s += "\n";
  }
  for (const auto& sc : r.scenarios)
    if (sc.scenario.name == "nominal")
      for (const auto& n : sc.screen_notes) s += "  screening: " + termText(n) + "\n";
  for (const auto& sc : r.scenarios)
    if (!sc.failure.empty()) s += "  scenario " + termText(sc.scenario.name) + ": " + termText(sc.failure) + "\n";
  s += "Total: " + points(r.score()) + "/" + points(r.maxScore()) + "\n";
  return s;
}

std::string markdownReport(const GradeReport& r) {
  const std::string file = std::filesystem::path(r.submission).filename().string();
  std::string md = "# dynlab grade: " + mdText(r.lab) + "\n\n";
  md += "Submission " + mdText(file) + ": **" + points(r.score()) + " / " + points(r.maxScore()) + " points**.\n\n";
  md += "| # | test | scenario | metric | value | full credit | zero credit | score |\n";
  md += "|---|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < r.tests.size(); ++i) {
    const GradedTest& g = r.tests[i];
    md += "| " + std::to_string(i + 1) + " | " + mdText(g.test.name) + " | " + mdText(g.test.scenario) + " | " +
          mdCode(g.test.metric) + " | " + (std::isfinite(g.value) ? mdUnit(g.value, g.unit) : "—") + " | " +
          mdUnit(g.test.full, g.unit) + " | " + mdUnit(g.test.zero, g.unit) + " | " + points(g.score) + " / " +
          points(g.test.points) + " |\n";
  }
  md += "\n## Tests\n";
  for (std::size_t i = 0; i < r.tests.size(); ++i) {
    const GradedTest& g = r.tests[i];
    md += "\n### " + std::to_string(i + 1) + ". " + mdText(g.test.name) + " — " + points(g.score) + " / " + points(g.test.points) + "\n\n";
    md += testText(r, g) + "\n";
    // The image is all ours (plots/NN-slug.png, alt text by number): the heading above names it.
    if (!g.plot.empty()) md += "\n![plot of test " + std::to_string(i + 1) + "](" + g.plot + ")\n";
  }
  md += "\n## Scenarios and gain screening\n\n";
  for (const auto& s : r.scenarios) {
    md += "- **" + mdText(s.scenario.name) + "** (" + mdText(s.scenario.about) + "): " + mdText(scenarioStatus(s)) + ".\n";
    for (const auto& n : s.screen_notes)
      if (!blank(n)) md += "  - " + mdText(n) + "\n";
  }
  md += "\n## Fingerprint\n\n";
  for (const auto& [k, v] : r.fingerprint.items())
    md += "- " + mdText(k) + ": " + mdCode(v.is_string() ? v.get<std::string>() : dumpJson(v)) + "\n";
  // The command to copy, with the file name in it when that holds no markup.
  const bool plain_name = file.find_first_of("<>&") == std::string::npos;
  md += "\nRe-check with " + mdCode("dynlab grade --replay results.json " + (plain_name ? shellWord(file) : "SUBMISSION")) +
        (plain_name ? "" : " (SUBMISSION: the file named above)") + ".\n";
  return md;
}

std::string renderHtml(const std::string& markdown, const std::string& title, const std::string& extra_css) {
  // GitHub-flavoured Markdown (tables) through cmark-gfm, safe mode (the default since 0.29; named
  // for older versions): raw HTML and javascript: links are dropped, not passed through.
  cmark_gfm_core_extensions_ensure_registered();
  const int options = CMARK_OPT_DEFAULT | CMARK_OPT_SAFE;
  cmark_parser* parser = cmark_parser_new(options);
  if (cmark_syntax_extension* table = cmark_find_syntax_extension("table")) cmark_parser_attach_syntax_extension(parser, table);
  cmark_parser_feed(parser, markdown.data(), markdown.size());
  cmark_node* doc = cmark_parser_finish(parser);
  char* body = cmark_render_html(doc, options, cmark_parser_get_syntax_extensions(parser));
  std::string html =
      "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>" + htmlText(title) + "</title>\n"
      "<style>body{font-family:sans-serif;max-width:60em;margin:2em auto;line-height:1.45}"
      "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:.25em .6em}"
      "img{max-width:100%}code{background:#f3f3f3;padding:0 .2em}" + extra_css + "</style></head><body>\n";
  html += body;
  html += "</body></html>\n";
  free(body);
  cmark_node_free(doc);
  cmark_parser_free(parser);
  return html;
}

void writeTestPlots(GradeReport& r, const std::map<std::string, ScenarioRun>& runs, const std::string& out_dir) {
  std::filesystem::create_directories(std::filesystem::path(out_dir) / "plots");
  for (std::size_t i = 0; i < r.tests.size(); ++i) {
    GradedTest& g = r.tests[i];
    if (!g.test.plot) continue;
    const PlotRequest& p = *g.test.plot;
    const ScenarioRun& run = runs.at(g.test.scenario);
    const Trace& tr = run.trace;
    if (tr.rows() < 2) continue;
    PlotSpec spec;
    spec.title = g.test.name + " (" + g.test.scenario + ")";
    spec.xlabel = "t (s)";
    spec.ylabel = p.ylabel;
    const std::vector<double> t = tr.series("t");
    if (!p.reference.empty() && tr.column(p.reference) >= 0) {
      const std::vector<double> ref = tr.series(p.reference);
      if (p.band > 0) {
        PlotBand band{"tolerance ±" + fmtNumber(p.band), t, ref, ref};
        for (std::size_t k = 0; k < ref.size(); ++k) band.lo[k] -= p.band, band.hi[k] += p.band;
        spec.bands.push_back(band);
      }
      spec.series.push_back({p.reference + " (reference)", t, ref, PlotSeries::Style::Dashed, 1});
    } else if (p.band > 0) {
      spec.bands.push_back({"limit ±" + fmtNumber(p.band), t, std::vector<double>(t.size(), -p.band),
                            std::vector<double>(t.size(), p.band)});
    }
    int color = 0;
    for (const auto& c : p.columns) {
      if (tr.column(c) < 0) continue;
      spec.series.push_back({c, t, tr.series(c), PlotSeries::Style::Solid, color == 1 ? 2 : color});
      color = color == 0 ? 2 : color + 1;
    }
    if (run.failure_time >= 0) {
      spec.vlines.push_back(run.failure_time);
      spec.vline_label = "run stopped";
    }
    char name[96];
    std::snprintf(name, sizeof name, "plots/%02zu-%s.png", i + 1, slug(g.test.name).c_str());
    writePlot((std::filesystem::path(out_dir) / name).string(), spec);
    g.plot = name;
  }
}

}  // namespace dyn
