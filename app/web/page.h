// The page's state (app/web/page_main.cpp) and what its HTML calls (page_api.cpp).
#pragma once
#include <memory>
#include <string>

#include "app/ui/frame.h"
#include "app/ui/session.h"
#include "render/window_context.h"

namespace dyn::web {

struct Page {
  std::string lab, load_error;
  std::unique_ptr<WindowContext> ctx;
  std::unique_ptr<ui::TuningSession> session;  // null when the lab cannot open in the page
  ui::PanelState st;
  ui::TuningFrame tuning;
  double last = 0;
  long frames = 0;
  bool grade_at_load = false, bench = false, probe = false;
};
Page& page();

// Opens LAB (with the gains or submission file when given) as the page's session; "" or the one
// line that says why not (e.g. a model-file lab without its exported description).
std::string openLab(const std::string& lab, const std::string& gains_file);
// Replaces the session (engines: both, the Bullet ghost drawn) and starts its run.
void useSession(std::unique_ptr<ui::TuningSession> session);
// Grades the submission file (empty: the session's gains, saved first) as `dynlab grade FILE --lab LAB
// --no-plots` does, prints one console line "dynlab results.json: {…}" and returns the text (2-space).
std::string gradeAndPrint(const std::string& submission_file);
// Runs the session's lab to its end with both engines and prints the steps per second.
void benchmark(ui::TuningSession& session);

}  // namespace dyn::web
