// libFuzzer target: arbitrary bytes as every text a grade report carries (the submission's file
// name, lab, scenario names and descriptions, run failures, screening notes, test and metric
// names, fingerprint keys and values) and as metric values, through the writers of results.json,
// report.md, report.html and the terminal summary, and through each escaping function alone.
// Asserted here, not just "no crash": results.json dumps and parses back; report.md has only its
// own headings and table rows; the HTML has no raw HTML from the text (cmark's "raw HTML omitted"
// never appears), no <script>, no <img> but the plots; the terminal has no control characters
// but its own line ends; a CSV field never starts with a formula character.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstdint>

#include "grading/escape.h"
#include "grading/report.h"
#include "tests/fuzz/fuzz_common.h"

using namespace dyn;

namespace {

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

std::size_t linesStartingWith(const std::string& text, const std::string& prefix) {
  return count("\n" + text, "\n" + prefix);
}

void checkEscapes(const std::string& s) {
  if (!isValidUtf8(jsonText(s))) fuzz::bug("jsonText is not valid UTF-8");
  const std::string md = mdText(s), code = mdCode(s), term = termText(s), csv = csvField(s);
  for (const std::string* t : {&md, &code, &term, &csv})
    if (!isValidUtf8(*t)) fuzz::bug("an escape gave invalid UTF-8");
  if (md.find('\n') != std::string::npos || code.find('\n') != std::string::npos) fuzz::bug("a line break in Markdown text");
  for (unsigned char c : term)
    if (c < 0x20 || c == 0x7f) fuzz::bug("a control character in terminal text");
  const std::string html = renderHtml("x " + md + "\n\ny " + code + "\n");
  if (html.find("<!-- raw HTML omitted") != std::string::npos || count(html, "<p>") != 2 || count(html, "<code>") != 1)
    fuzz::bug("Markdown escaping let a construct through: " + html);
  const char first = csv.size() > 1 && csv[0] == '"' ? csv[1] : csv.empty() ? 'x' : csv[0];
  if (std::string("=+-@\t\r").find(first) != std::string::npos) fuzz::bug("a CSV field starting a formula");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  const auto text = [&] { return in.ConsumeRandomLengthString(64); };
  checkEscapes(text());

  GradeReport r;
  r.lab = text();
  r.submission = text();
  const std::size_t scenarios = in.ConsumeIntegralInRange<std::size_t>(1, 3);
  for (std::size_t i = 0; i < scenarios; ++i) {
    ScenarioSummary s;
    s.scenario.name = i == 0 ? "nominal" : text();
    s.scenario.about = text();
    if (in.ConsumeBool()) s.failure = text(), s.failure_time = in.ConsumeFloatingPoint<double>();
    for (int k = in.ConsumeIntegralInRange(0, 2); k > 0; --k) s.screen_notes.push_back(text());
    s.metrics[text()] = in.ConsumeFloatingPoint<double>();
    r.scenarios.push_back(s);
  }
  const std::size_t tests = in.ConsumeIntegralInRange<std::size_t>(0, 3);
  for (std::size_t i = 0; i < tests; ++i) {
    GradedTest g;
    g.test.name = text();
    g.test.scenario = r.scenarios[in.ConsumeIntegralInRange<std::size_t>(0, scenarios - 1)].scenario.name;
    g.test.metric = text();
    g.test.full = in.ConsumeFloatingPoint<double>();
    g.test.zero = in.ConsumeFloatingPoint<double>();
    g.test.points = in.ConsumeFloatingPointInRange<double>(0, 100);
    g.value = in.ConsumeBool() ? in.ConsumeFloatingPoint<double>() : NAN;
    g.note = text();
    g.score = in.ConsumeFloatingPointInRange<double>(0, 100);
    if (in.ConsumeBool()) g.plot = "plots/0" + std::to_string(i + 1) + "-plot.png";  // the grader's own names
    r.tests.push_back(g);
  }
  r.fingerprint = json::object();
  r.fingerprint[text()] = text();

  // results.json: dumps (the strict dump, not the replacing one) and reads back the same.
  const json results = resultsJson(r);
  std::string dumped;
  try {
    dumped = results.dump(2);
  } catch (const std::exception& e) {
    fuzz::bug(std::string("results.json does not dump: ") + e.what());
  }
  if (json::parse(dumped) != results) fuzz::bug("results.json does not read back");
  if (results.at("tests").size() != tests) fuzz::bug("results.json lost a test");

  // report.md: its own headings only (title, three sections, one per test) and one table row per test.
  const std::string md = markdownReport(r);
  if (!isValidUtf8(md)) fuzz::bug("report.md is not valid UTF-8");
  if (linesStartingWith(md, "# ") != 1 || linesStartingWith(md, "## ") != 3 || linesStartingWith(md, "### ") != tests ||
      linesStartingWith(md, "#") != 4 + tests)
    fuzz::bug("report.md headings do not match the report:\n" + md);
  if (linesStartingWith(md, "| ") != tests + 1) fuzz::bug("report.md table rows do not match the tests:\n" + md);

  // report.html: what cmark made of it holds nothing but our own structure.
  const std::string html = renderHtml(md, r.lab);
  std::size_t plots = 0;
  for (const auto& g : r.tests) plots += !g.plot.empty();
  if (html.find("<!-- raw HTML omitted") != std::string::npos || html.find("<script") != std::string::npos ||
      count(html, "<img") != plots || count(html, "<h1>") != 1 || count(html, "<h2>") != 3 || count(html, "<h3>") != tests ||
      count(html, "<tr>") != tests + 1)
    fuzz::bug("report.html does not match the report:\n" + html);

  // The terminal: one line per test, note and failure, plus the header and the total.
  const std::string term = terminalReport(r);
  for (unsigned char c : term)
    if ((c < 0x20 && c != '\n') || c == 0x7f) fuzz::bug("a control character in the terminal report");
  std::size_t lines = 2 + tests;
  for (const auto& s : r.scenarios) lines += (s.scenario.name == "nominal" ? s.screen_notes.size() : 0) + !s.failure.empty();
  if (count(term, "\n") != lines) fuzz::bug("the terminal report has extra lines:\n" + term);
  return 0;
}
