// The tuning panel (Dear ImGui, interactive): play/pause/restart/speed, engine, the lab's gains as
// sliders within their declared bounds, its submission options, live plots, running metrics and
// screening, problems in plain words, and "Save gains…" with the command that grades the file.
// It reads and changes a TuningSession only; the window loop (main.cpp) owns time and drawing.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "app/ui/session.h"

namespace dyn::ui {

struct PanelState {
  bool playing = true;
  bool loop = false;               // restart when the run ends
  bool restart_on_change = true;   // a changed gain or option restarts the run at once
  bool pending_changes = false;    // changed since the last restart (restart_on_change off)
  double speed = 1.0;              // simulated seconds per wall second
  std::string save_path;           // what "Save gains…" writes
  std::string saved_path;          // the last file written ("" until then)
  std::string status;              // last save result
  // Called with the path after "Save gains…" wrote it (the page offers the file as a download).
  std::function<void(const std::string& path)> saved;
  bool status_is_error = false;
  int plot_column = -1;            // extra live plot: a trace column chosen by the student
  // Where the last frame drew each gain's slider (window pixels: frame, then its name's text),
  // for --state and the tests that check names and value digits stay readable.
  struct Widget {
    std::string name;
    float frame[4] = {0, 0, 0, 0}, label[4] = {0, 0, 0, 0};  // x0, y0, x1, y1
  };
  std::vector<Widget> widgets;
  float window_right = 0;          // the panel's right edge (window pixels)
};

// Saves the session's gains to state.save_path and records the outcome in state.status.
void saveGains(TuningSession& session, PanelState& state);

// Draws the panel as a fixed window at (x, 0) of size width × height (window pixels).
void drawTuningPanel(TuningSession& session, PanelState& state, float x, float width, float height);

}  // namespace dyn::ui
