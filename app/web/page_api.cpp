// What index.html calls in the page (exported C functions, called through Module.ccall) and the
// work behind the link's &grade=1 and &bench=1: open a lab, load uploaded gains, grade (the native
// grader's code, grading/grade.h), the handout (app/cli/course's, the same text `dynlab handout`
// writes), the list of labs.
#include <emscripten.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <utility>

#include "app/cli/course/course.h"
#include "app/web/page.h"
#include "grading/escape.h"
#include "grading/grade.h"
#include "grading/report.h"
#include "labs/lab.h"

namespace dyn::web {

std::string openLab(const std::string& lab, const std::string& gains_file) {
  if (!findLab(lab)) return "no lab \"" + lab + "\" here: choose one from the list";
  try {
    useSession(std::make_unique<ui::TuningSession>(lab, "", gains_file));
    return "";
  } catch (const InputError& e) {
    // The lab's model file (or its description) cannot be read here: the lab's fault, not the gains'.
    if (e.path() == "/model_file") return lab + " cannot open in the page: " + e.what();
    return std::string("error: ") + e.what();
  } catch (const std::exception& e) {
    // A lab that cannot run here (e.g. a model file without its exported description: the page has no
    // MuJoCo parser): one line, the lab stays listed.
    return lab + " cannot open in the page: " + e.what();
  }
}

std::string gradeAndPrint(const std::string& submission_file) {
  Page& p = page();
  std::string file = submission_file;
  try {
    if (file.empty()) {
      file = "/tmp/" + p.lab + "_submission.json";
      p.session->saveSubmission(file);
    }
  } catch (const std::exception& e) {
    std::printf("dynlab page: cannot grade: %s\n", e.what());
    return std::string("error: ") + e.what();
  }
  GradeOptions options;
  options.expected_lab = p.lab;
  const GradeOutcome g = gradeSubmission(file, options);
  if (!g.error.empty()) std::printf("dynlab page: grade: %s\n", g.error.c_str());
  std::printf("dynlab results.json: %s\n", dumpJson(g.results).c_str());
  std::fflush(stdout);
  return dumpJson(g.results, 2);
}

namespace {

// The lab's whole run, timed: steps and seconds.
std::pair<long, double> timedRun(ui::TuningSession& session) {
  session.restart();
  const auto start = std::chrono::steady_clock::now();
  long steps = 0;
  while (!session.finished()) steps += session.advance(1000);
  return {steps, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
}

}  // namespace

// The run five times, both engines: the first (cold) runs mostly in V8's baseline code (Liftoff) while
// its optimizing tier (TurboFan) compiles the hot functions in the background, and is what a student's
// first run gets; the fastest of the four after it (warm), what the later runs of the session get
// (docs/performance.md, the page). One console line, which page_check.js waits for.
void benchmark(ui::TuningSession& session) {
  session.setEngine(ui::EngineChoice::Both);
  const double dt = session.lab() ? session.lab()->dt() : 0;
  const std::pair<long, double> first = timedRun(session);
  const long steps = first.first;
  const double cold = first.second;
  const std::string problem = session.problem();
  double warm = 0;
  for (int again = 0; again < 4; ++again) {
    const double s = timedRun(session).second;
    warm = again == 0 ? s : std::min(warm, s);
  }
  auto rate = [&](double wall) { return steps / std::max(wall, 1e-9); };
  std::printf("dynlab bench: %s %ld steps (hand and Bullet) in %.3f s: %.0f steps/s, %.1fx real time%s; warm (fastest of the next 4 runs): "
              "%.3f s, %.0f steps/s, %.1fx real time\n",
              session.labName().c_str(), steps, cold, rate(cold), rate(cold) * dt, problem.empty() ? "" : " (the run stopped early)", warm,
              rate(warm), rate(warm) * dt);
  session.restart();
}

}  // namespace dyn::web

namespace {

// The text a call returns stays valid until the next call of the same function.
const char* keep(std::string& slot, std::string text) {
  slot = std::move(text);
  return slot.c_str();
}

}  // namespace

extern "C" {

// [{"name", "summary"}] of every registered lab, and which one is open: {"labs": [...], "open", "error"}.
EMSCRIPTEN_KEEPALIVE const char* dynlab_labs() {
  static std::string out;
  dyn::json labs = dyn::json::array();
  for (const auto& e : dyn::labRegistry()) labs.push_back({{"name", e.name}, {"summary", e.summary}});
  const dyn::web::Page& p = dyn::web::page();
  return keep(out, dyn::dumpJson({{"labs", labs}, {"open", p.lab}, {"error", p.load_error}}));
}

// Loads a submission or gains JSON the student chose (its file name and text): "" or the one line that
// says why not, naming the file (the run and gains already open stay).
EMSCRIPTEN_KEEPALIVE const char* dynlab_load_gains(const char* name, const char* text) {
  static std::string out;
  std::string base;
  for (const char* c = name; *c && base.size() < 80; ++c) base += std::isalnum(static_cast<unsigned char>(*c)) || *c == '.' || *c == '-' ? *c : '_';
  ::mkdir("/uploads", 0755);
  const std::string path = "/uploads/" + (base.empty() || base[0] == '.' ? "gains.json" : base);
  {
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f << text;
  }
  return keep(out, dyn::web::openLab(dyn::web::page().lab, path));
}

// Grades the gains in the panel (results.json, 2-space indented); also printed as one console line.
EMSCRIPTEN_KEEPALIVE const char* dynlab_grade() {
  static std::string out;
  if (!dyn::web::page().session) return keep(out, "error: no lab is open");
  return keep(out, dyn::web::gradeAndPrint(""));
}

// The lab's handout as a standalone HTML page (what `dynlab handout LAB --format html` writes).
EMSCRIPTEN_KEEPALIVE const char* dynlab_handout() {
  static std::string out;
  try {
    dyn::app::HandoutArgs a;
    a.lab = dyn::web::page().lab;
    const dyn::app::HandoutText text = dyn::app::handoutText(a);
    return keep(out, dyn::renderHtml(text.markdown, text.title + " — handout", "td,th{vertical-align:top}"));
  } catch (const std::exception& e) {
    return keep(out, std::string("<p>No handout: ") + dyn::htmlText(e.what()) + "</p>");
  }
}

}  // extern "C"
