// Results, terminal, Markdown and HTML forms of a grade; plots of each test's response.
#include "grading/report.h"

#include <cmark-gfm-core-extensions.h>
#include <cmark-gfm.h>

#include <algorithm>
#include <filesystem>
#include <vector>

#include "grading/escape.h"
#include "grading/grade.h"

namespace dyn {
namespace {

const ScenarioSummary& scenarioOf(const GradeReport& r, const std::string& name) {
  for (const auto& s : r.scenarios)
    if (s.scenario.name == name) return s;
  throw std::logic_error("no scenario " + name);
}

std::string points(double x) { return fmtNumber(std::round(x * 100) / 100); }

// A metric's value with its unit, as feedback shows it ("0.01113 m"; dimensionless: the number). The
// number is plain digits; the unit (from the lab's JSON) is escaped for where it lands.
std::string withUnit(double x, const std::string& unit, std::string (*escape)(const std::string&)) {
  return fmtNumber(x) + (unit.empty() || unit == "1" ? "" : " " + escape(unit));
}
std::string mdUnit(double x, const std::string& unit) { return withUnit(x, unit, [](const std::string& u) { return mdText(u); }); }
std::string termUnit(double x, const std::string& unit) { return withUnit(x, unit, [](const std::string& u) { return termText(u); }); }

// A test below its points: its advice is shown.
bool shortOfFull(const GradedTest& g) { return g.score < g.test.points - 1e-9; }

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
  if (shortOfFull(g) && !g.advice.empty())
    s += " **What to change:** " + mdText(g.advice) + (g.advice.back() == '.' ? "" : ".");
  return s;
}

// A note with nothing to show is left out: an empty "- " item under a line would make it a heading.
bool blank(const std::string& s) { return s.find_first_not_of(" \t") == std::string::npos; }

std::string scenarioStatus(const ScenarioSummary& s) { return s.failure.empty() ? "completed" : s.failure; }

// The paragraph of a test's output that holds its plot (or says why it does not): marked by its
// class, which cmark never writes, so withoutInlinePlots finds exactly it.
const std::string kPlotParagraph = "<p class=\"dynlab-plot\">";

// A PNG's size from its IHDR chunk (0 × 0 if it is not a PNG).
std::pair<unsigned, unsigned> pngSize(const std::string& png) {
  if (png.size() < 24 || png.compare(12, 4, "IHDR") != 0) return {0, 0};
  const auto u32 = [&](std::size_t at) {
    unsigned v = 0;
    for (std::size_t k = 0; k < 4; ++k) v = v << 8 | static_cast<unsigned char>(png[at + k]);
    return v;
  };
  return {u32(16), u32(20)};
}

// The plot paragraph of test i: the image inline while the budget lasts, else a note.
std::string inlinePlot(const GradedTest& g, std::size_t i, std::size_t& budget) {
  const std::string uri = pngDataUri(g.plot_png);
  if (uri.size() > budget)
    return kPlotParagraph + "<em>(The plot of this test is left out: the feedback holds at most " +
           std::to_string(kMaxInlinePlotBytes / 1024) + " KB of plots.)</em></p>\n";
  budget -= uri.size();
  const auto [w, h] = pngSize(g.plot_png);
  const std::string size = w && h ? " width=\"" + std::to_string(w) + "\" height=\"" + std::to_string(h) + "\"" : "";
  return kPlotParagraph + "<img alt=\"plot of test " + std::to_string(i + 1) + "\"" + size + " src=\"" + uri + "\"></p>\n";
}

}  // namespace

std::string answersMarkdown(const json& answers) {
  if (answers.empty()) return {};
  // Each answer a quoted block, one escaped line per line of the student's text.
  std::string md = "\n## Your answers\n";
  for (const auto& [name, text] : answers.items()) {
    md += "\n**" + mdText(name) + "**\n\n";
    const std::string t = text.get<std::string>();
    for (std::size_t at = 0; at <= t.size();) {
      std::size_t end = t.find('\n', at);
      if (end == std::string::npos) end = t.size();
      std::string line = t.substr(at, end - at);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      md += "> " + mdText(line) + "  \n";
      at = end + 1;
    }
  }
  return md;
}

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

namespace {
// The student's plant in words; a lab without variants has one plant for every student.
std::string plantShown(const GradeReport& r) {
  return r.plant.empty() ? "the same for every student (the lab declares no variants)" : plantText(r.plant);
}
}  // namespace

json resultsJson(const GradeReport& r) {
  json tests = json::array();
  std::size_t budget = kMaxInlinePlotBytes;
  for (std::size_t i = 0; i < r.tests.size(); ++i) {
    const GradedTest& g = r.tests[i];
    json extra = {{"scenario", g.test.scenario}, {"metric", g.test.metric}, {"full", g.test.full}, {"zero", g.test.zero}};
    extra["value"] = std::isfinite(g.value) ? json(g.value) : json(nullptr);
    if (!g.plot.empty()) extra["plot"] = g.plot;
    tests.push_back({{"name", g.test.name},
                     {"number", std::to_string(i + 1)},
                     {"score", g.score},
                     {"max_score", g.test.points},
                     // Gradescope paints "failed" red: only a test that earned nothing is (0.94 / 1 is not).
                     {"status", g.score > 1e-9 ? "passed" : "failed"},
                     {"output", renderHtmlFragment(testText(r, g)) +
                                    (r.inline_plots && !g.plot_png.empty() ? inlinePlot(g, i, budget) : "")},
                     {"output_format", "html"},
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
  if (!r.student.empty()) output += "Graded on the plant of student " + mdText(r.student) + ": " + mdText(plantShown(r)) + ".\n\n";
  for (const auto& s : r.scenarios) {
    if (s.scenario.name != "nominal") continue;
    for (const auto& n : s.screen_notes)
      if (!blank(n)) output += "- " + mdText(n) + "\n";
  }
  for (const auto& s : r.scenarios)
    if (!s.failure.empty()) output += "- Scenario **" + mdText(s.scenario.name) + "**: " + mdText(s.failure) + ".\n";
  if (!r.plots_note.empty()) output += "- " + mdText(r.plots_note) + "\n";
  json results = {{"score", r.score()},
                  {"output", output},
                  {"output_format", "md"},
                  {"test_output_format", "html"},
                  {"visibility", "visible"},
                  {"stdout_visibility", "hidden"},
                  {"tests", tests},
                  {"extra_data", {{"lab", r.lab}, {"fingerprint", r.fingerprint}, {"scenarios", scenarios}}}};
  if (!r.answers.empty()) results["extra_data"]["answers"] = r.answers;
  if (!r.student.empty()) {
    results["extra_data"]["student"] = r.student;
    json plant = json::object();
    for (const PlantValue& v : r.plant) plant[v.parameter.path] = v.value;
    results["extra_data"]["plant"] = plant;
  }
  if (!r.plots_note.empty()) results["extra_data"]["plots_note"] = r.plots_note;
  if (!r.leaderboard.empty()) results["leaderboard"] = r.leaderboard;
  return jsonSanitized(results);  // names, notes and keys as valid UTF-8: dump() cannot throw
}

std::string terminalReport(const GradeReport& r) {
  std::string s = "Grading " + termText(r.submission) + " (" + termText(r.lab) + ")\n";
  if (!r.student.empty()) s += "  plant of student " + termText(r.student) + ": " + termText(plantShown(r)) + "\n";
  for (const auto& g : r.tests) {
    s += "  " + points(g.score) + "/" + points(g.test.points) + "  " + termText(g.test.name) + " [" + termText(g.test.scenario) + "]: ";
    s += std::isfinite(g.value) ? termText(g.test.metric) + " = " + termUnit(g.value, g.unit) + " (full " +
                                      termUnit(g.test.full, g.unit) + ", zero " + termUnit(g.test.zero, g.unit) + ")"
                                : termText(g.note);
    s += "\n";
    if (shortOfFull(g) && !g.advice.empty()) s += "        → " + termText(g.advice) + "\n";
  }
  for (const auto& sc : r.scenarios)
    if (sc.scenario.name == "nominal")
      for (const auto& n : sc.screen_notes) s += "  screening: " + termText(n) + "\n";
  for (const auto& sc : r.scenarios)
    if (!sc.failure.empty()) s += "  scenario " + termText(sc.scenario.name) + ": " + termText(sc.failure) + "\n";
  if (!r.plots_note.empty()) s += "  plots: " + termText(r.plots_note) + "\n";
  if (!r.answers.empty()) s += "  answers: " + std::to_string(r.answers.size()) + " written answer(s), in report.md for the course staff\n";
  s += "Total: " + points(r.score()) + "/" + points(r.maxScore()) + "\n";
  return s;
}

std::string markdownReport(const GradeReport& r) {
  const std::string file = std::filesystem::path(r.submission).filename().string();
  std::string md = "# dynlab grade: " + mdText(r.lab) + "\n\n";
  md += "Submission " + mdText(file) + ": **" + points(r.score()) + " / " + points(r.maxScore()) + " points**.\n\n";
  if (!r.student.empty()) md += "Graded on the plant of student " + mdText(r.student) + ": " + mdText(plantShown(r)) + ".\n\n";
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
  if (!r.plots_note.empty()) md += "\n" + mdText(r.plots_note) + "\n";
  for (std::size_t i = 0; i < r.tests.size(); ++i) {
    const GradedTest& g = r.tests[i];
    md += "\n### " + std::to_string(i + 1) + ". " + mdText(g.test.name) + " — " + points(g.score) + " / " + points(g.test.points) + "\n\n";
    md += testText(r, g) + "\n";
    // The image is all ours (plots/NN-slug.png, alt text by number): the heading above names it.
    if (!g.plot.empty()) md += "\n![plot of test " + std::to_string(i + 1) + "](" + g.plot + ")\n";
  }
  md += answersMarkdown(r.answers);
  md += "\n## Scenarios and gain screening\n\n";
  for (const auto& s : r.scenarios) {
    md += "- **" + mdText(s.scenario.name) + "** (" + mdText(s.scenario.about) + "): " + mdText(scenarioStatus(s)) + ".\n";
    for (const auto& n : s.screen_notes)
      if (!blank(n)) md += "  - " + mdText(n) + "\n";
  }
  md += "\n## Fingerprint\n\n";
  for (const auto& [k, v] : r.fingerprint.items())
    md += "- " + mdText(k) + ": " + mdCode(v.is_string() ? v.get<std::string>() : dumpJson(v)) + "\n";
  // The command to copy: the grader's own (absolute, quoted paths) when it holds nothing a code
  // span or the page could mangle, else a generic one.
  const std::string command = r.replay.empty() ? "dynlab grade --replay results.json " + shellWord(file) : r.replay;
  const bool plain = std::none_of(command.begin(), command.end(), [](unsigned char c) {
    return c < 0x20 || c == 0x7f || c == '<' || c == '>' || c == '&' || c == '|' || c == '`';
  });
  md += "\nRe-check with " + mdCode(plain ? command : "dynlab grade --replay results.json SUBMISSION") +
        (plain ? "" : " (SUBMISSION: the file named above)") + ".\n";
  return md;
}

std::string renderHtmlFragment(const std::string& markdown) {
  // GitHub-flavoured Markdown (tables) through cmark-gfm, safe mode (the default since 0.29; named
  // for older versions): raw HTML and javascript: links are dropped, not passed through (data:
  // URIs of PNG, GIF, JPEG and WebP images are kept).
  cmark_gfm_core_extensions_ensure_registered();
  const int options = CMARK_OPT_DEFAULT | CMARK_OPT_SAFE;
  cmark_parser* parser = cmark_parser_new(options);
  // Tables, and autolinks as GitHub and Gradescope make them: reflected text must stay inert under them.
  for (const char* name : {"table", "autolink"})
    if (cmark_syntax_extension* ext = cmark_find_syntax_extension(name)) cmark_parser_attach_syntax_extension(parser, ext);
  cmark_parser_feed(parser, markdown.data(), markdown.size());
  cmark_node* doc = cmark_parser_finish(parser);
  char* body = cmark_render_html(doc, options, cmark_parser_get_syntax_extensions(parser));
  std::string html = body;
  free(body);
  cmark_node_free(doc);
  cmark_parser_free(parser);
  return html;
}

std::string renderHtml(const std::string& markdown, const std::string& title, const std::string& extra_css) {
  std::string html =
      "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>" + htmlText(title) + "</title>\n"
      "<style>body{font-family:sans-serif;max-width:60em;margin:2em auto;line-height:1.45}"
      "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:.25em .6em}"
      "img{max-width:100%}code{background:#f3f3f3;padding:0 .2em}" + extra_css + "</style></head><body>\n";
  html += renderHtmlFragment(markdown);
  html += "</body></html>\n";
  return html;
}

std::string reportHtml(const GradeReport& r, const std::string& markdown, const std::string& title) {
  // cmark renders the links (small), then each becomes its image's bytes: the grader's own file
  // names (plots/NN-slug.png) need no escaping and appear nowhere else as a src (nor in the base64
  // that replaces one, which has no quotes). Put together in one pass: replacing in place moved the
  // growing page's tail once per plot.
  const std::string html = renderHtml(markdown, title);
  struct Swap {
    std::size_t at, size;
    const std::string* png;
  };
  std::vector<Swap> swaps;
  for (const auto& g : r.tests) {
    if (g.plot.empty() || g.plot_png.empty()) continue;
    const std::string link = "src=\"" + g.plot + "\"";
    if (const std::size_t at = html.find(link); at != std::string::npos) swaps.push_back({at, link.size(), &g.plot_png});
  }
  std::sort(swaps.begin(), swaps.end(), [](const Swap& a, const Swap& b) { return a.at < b.at; });
  std::string out;
  std::size_t size = html.size();
  for (const Swap& s : swaps) size += s.png->size() / 3 * 4 + 64;
  out.reserve(size);
  std::size_t from = 0;
  for (const Swap& s : swaps) {
    out.append(html, from, s.at - from).append("src=\"").append(pngDataUri(*s.png)).append("\"");
    from = s.at + s.size;
  }
  return out.append(html, from, std::string::npos);
}

std::string pngDataUri(const std::string& png) {
  static const char* kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const std::string head = "data:image/png;base64,";
  std::string out(head.size() + (png.size() + 2) / 3 * 4, '=');
  std::copy(head.begin(), head.end(), out.begin());
  char* o = out.data() + head.size();
  const auto byte = [&](std::size_t i) { return unsigned(static_cast<unsigned char>(png[i])); };
  std::size_t i = 0;
  for (; i + 3 <= png.size(); i += 3, o += 4) {  // three bytes → four digits
    const unsigned v = byte(i) << 16 | byte(i + 1) << 8 | byte(i + 2);
    o[0] = kDigits[v >> 18], o[1] = kDigits[(v >> 12) & 63], o[2] = kDigits[(v >> 6) & 63], o[3] = kDigits[v & 63];
  }
  if (const std::size_t n = png.size() - i; n > 0) {  // a short last group, padded with '='
    const unsigned v = byte(i) << 16 | (n > 1 ? byte(i + 1) << 8 : 0u);
    o[0] = kDigits[v >> 18], o[1] = kDigits[(v >> 12) & 63];
    if (n > 1) o[2] = kDigits[(v >> 6) & 63];
  }
  return out;
}

json withoutInlinePlots(json results) {
  // A note that the plots could not be drawn (extra_data and its line in the output) is about plots too.
  if (results.contains("extra_data") && results["extra_data"].is_object() && results["extra_data"].contains("plots_note")) {
    const json note = results["extra_data"]["plots_note"];
    results["extra_data"].erase("plots_note");
    if (note.is_string() && results.contains("output") && results["output"].is_string()) {
      std::string out = results["output"];
      const std::string line = "- " + mdText(note.get<std::string>()) + "\n";
      if (const std::size_t at = out.find(line); at != std::string::npos) out.erase(at, line.size());
      results["output"] = out;
    }
  }
  if (!results.contains("tests") || !results["tests"].is_array()) return results;
  for (auto& t : results["tests"]) {
    if (!t.is_object() || !t.contains("output") || !t["output"].is_string()) continue;
    std::string out = t["output"];
    for (std::size_t at; (at = out.find(kPlotParagraph)) != std::string::npos;) {
      const std::size_t end = out.find("</p>\n", at);
      out.erase(at, end == std::string::npos ? std::string::npos : end + 5 - at);
    }
    t["output"] = out;
  }
  return results;
}

}  // namespace dyn
