// The tuning panel: one fixed Dear ImGui window on the right of the scene; see panel.h. Sections:
// run, problems, gains, options, plots, metrics and screening, submission.
#include "app/ui/panel.h"

#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cstdio>

#include "labs/numbers.h"
#include "labs/utf8.h"
#include "render/plot_widget.h"

namespace dyn::ui {
namespace {

const ImVec4 kError(0.78f, 0.12f, 0.10f, 1.0f), kWarn(0.70f, 0.40f, 0.00f, 1.0f);
const ImVec4 kOk(0.10f, 0.50f, 0.20f, 1.0f), kMuted(0.40f, 0.43f, 0.48f, 1.0f);

// A shell word: quoted only when it needs to be.
std::string shellWord(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./+") == std::string::npos)
    return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Text from the lab's files or the model file (its title, gain and option names, trace columns,
// messages quoting them) as the panel shows it: control and bidi characters as escapes, and a long
// one clipped (termName), so no name is measured or drawn 200,000 characters long.
std::string shown(const std::string& s, std::size_t max_bytes = 200) { return termName(s, max_bytes); }

void tooltip(const std::string& text) {
  if (!ImGui::IsItemHovered()) return;
  ImGui::BeginTooltip();
  ImGui::PushTextWrapPos(ImGui::GetFontSize() * 32.0f);
  ImGui::TextUnformatted(text.c_str());
  ImGui::PopTextWrapPos();
  ImGui::EndTooltip();
}

// The room right of each slider for its name: the longest name the panel shows, measured.
float label_room = 70;

// A gain or option changed: restart at once, or remember that a restart is due.
void changed(TuningSession& session, PanelState& st) {
  if (st.restart_on_change) {
    session.restart();
    st.pending_changes = false;
  } else {
    st.pending_changes = true;
  }
}

void restart(TuningSession& session, PanelState& st) {
  session.restart();
  st.pending_changes = false;
}

void runSection(TuningSession& session, PanelState& st) {
  const Lab* lab = session.lab();
  const char* state = !session.problem().empty() ? "stopped" : session.finished() ? "finished" : st.playing ? "playing" : "paused";
  ImGui::Text("t = %.3f / %.3f s   (%s)", session.time(), lab ? lab->duration() : 0.0, state);
  if (session.finished()) {
    if (ImGui::Button("Replay", ImVec2(70, 0))) {
      restart(session, st);
      st.playing = true;
    }
    tooltip("run again from t = 0");
  } else {
    if (ImGui::Button(st.playing ? "Pause" : "Play", ImVec2(70, 0))) st.playing = !st.playing;
    tooltip("Space");
  }
  ImGui::SameLine();
  if (ImGui::Button("Restart", ImVec2(70, 0))) restart(session, st);
  tooltip("R: run again from t = 0 with the current gains");
  ImGui::SameLine();
  ImGui::BeginDisabled(st.playing || session.finished());
  if (ImGui::Button("Step", ImVec2(70, 0))) session.advance(1);
  ImGui::EndDisabled();
  tooltip("one time step (while paused)");
  ImGui::SameLine();
  ImGui::Checkbox("loop", &st.loop);
  tooltip("start again when the run ends");
  const double lo = 0.02, hi = 20.0;
  ImGui::SetNextItemWidth(-label_room);
  ImGui::SliderScalar("speed", ImGuiDataType_Double, &st.speed, &lo, &hi, "%.2fx",
                      ImGuiSliderFlags_Logarithmic | ImGuiSliderFlags_AlwaysClamp);
  tooltip("simulated seconds per second of wall time; the physics always uses the lab's fixed dt");
  ImGui::TextUnformatted("engine");
  const EngineChoice engines[] = {EngineChoice::Hand, EngineChoice::Bullet, EngineChoice::Both};
  const char* labels[] = {"hand", "bullet", "both (Bullet ghost)"};
  for (int i = 0; i < 3; ++i) {
    ImGui::SameLine();
    if (ImGui::RadioButton(labels[i], session.engine() == engines[i]) && session.engine() != engines[i]) {
      session.setEngine(engines[i]);
      restart(session, st);
    }
  }
}

void problemSection(const TuningSession& session) {
  if (!session.problem().empty()) {
    ImGui::Separator();
    ImGui::PushStyleColor(ImGuiCol_Text, kError);
    ImGui::TextWrapped("The run stopped: %s", shown(session.problem(), 1000).c_str());
    ImGui::PopStyleColor();
    ImGui::TextWrapped("These gains would score 0 in this scenario. Lower them (see the screening below) or "
                       "choose another option, then Restart.");
  }
  if (!session.ghostProblem().empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, kWarn);
    ImGui::TextWrapped("%s", shown(session.ghostProblem(), 1000).c_str());
    ImGui::PopStyleColor();
  }
}

void gainsSection(TuningSession& session, PanelState& st) {
  if (!ImGui::CollapsingHeader("Gains", ImGuiTreeNodeFlags_DefaultOpen)) return;
  for (const GainSpec& g : session.gainSpecs()) {
    double v = session.gain(g.name);
    std::string format = g.unit.empty() || g.unit == "1" ? "%.4g" : "%.4g " + g.unit;  // "1": dimensionless
    for (std::size_t p = format.find('%', 1); p != std::string::npos; p = format.find('%', p + 2)) format.insert(p, "%");
    ImGui::SetNextItemWidth(-label_room);
    if (ImGui::SliderScalar(shown(g.name).c_str(), ImGuiDataType_Double, &v, &g.min, &g.max, format.c_str(),
                            ImGuiSliderFlags_Logarithmic | ImGuiSliderFlags_AlwaysClamp))
      session.setGain(g.name, std::clamp(v, g.min, g.max));
    {
      const ImVec2 a = ImGui::GetItemRectMin(), b = ImGui::GetItemRectMax();
      const float frame_right = a.x + ImGui::CalcItemWidth();
      PanelState::Widget w;
      w.name = g.name;
      const float lx = frame_right + ImGui::GetStyle().ItemInnerSpacing.x;
      const float fr[4] = {a.x, a.y, frame_right, b.y}, lb[4] = {lx, a.y, lx + ImGui::CalcTextSize(shown(g.name).c_str()).x, b.y};
      std::copy(fr, fr + 4, w.frame), std::copy(lb, lb + 4, w.label);
      st.widgets.push_back(w);
    }
    if (ImGui::IsItemDeactivatedAfterEdit()) changed(session, st);
    tooltip(shown(g.doc, 1000) + "\nunit: " + shown(g.unit) + "\nrange [" + fmt("%.4g", g.min) + ", " + fmt("%.4g", g.max) +
            "], lab default " + fmt("%.4g", g.lab_default) + "\nCtrl+click to type a value.");
  }
  for (const OptionSpec& o : session.optionSpecs()) {
    const std::string current = session.option(o.name);
    ImGui::SetNextItemWidth(-label_room);
    if (ImGui::BeginCombo(shown(o.name).c_str(), shown(current).c_str())) {
      for (const auto& c : o.choices) {
        if (ImGui::Selectable(shown(c).c_str(), c == current) && c != current) {
          session.setOption(o.name, c);
          changed(session, st);
        }
      }
      ImGui::EndCombo();
    }
    tooltip(shown(o.doc, 1000) + "\nchoices: " + [&] {
      std::string l;
      for (const auto& c : o.choices) l += (l.empty() ? "" : ", ") + c;
      return shown(l, 1000);
    }() + "\nlab default: " + shown(o.lab_default));
  }
  if (ImGui::Button("Lab defaults")) {
    session.resetToLabDefaults();
    changed(session, st);
  }
  tooltip("every gain and option back to the lab's JSON");
  ImGui::SameLine();
  ImGui::Checkbox("restart on change", &st.restart_on_change);
  if (st.pending_changes) {
    ImGui::TextColored(kWarn, "changed since the run started:");
    ImGui::SameLine();
    if (ImGui::SmallButton("Restart to apply")) restart(session, st);
  }
}

void plotsSection(const TuningSession& session, PanelState& st) {
  if (!ImGui::CollapsingHeader("Live plots", ImGuiTreeNodeFlags_DefaultOpen)) return;
  const Lab* lab = session.lab();
  if (!lab || !session.hasRows()) {
    ImGui::TextColored(kMuted, "no run");
    return;
  }
  const Trace& tr = session.primary();
  // The lab's own plots, then the chosen column: every step up to the row on screen.
  const std::vector<Series> plots = session.livePlots(st.plot_column);
  const float width = ImGui::GetContentRegionAvail().x;
  float gutter = 0;
  for (const Series& s : plots) gutter = std::max(gutter, plotGutter(s.values));
  for (std::size_t i = 0; i < plots.size(); ++i) {
    const Series& s = plots[i];
    ImGui::TextColored(ImVec4(s.color.r, s.color.g, s.color.b, 1.0f), "%s", shown(s.name).c_str());
    if (!s.values.empty()) {
      ImGui::SameLine();
      ImGui::Text("%.4g", double(s.values.back()));
    }
    ImGui::PushID(int(i));
    plotWithScale("##plot", s.values, s.color, width, 60, 1.0f, gutter);
    ImGui::PopID();
  }
  // Any column of the trace over the last two seconds.
  ImGui::SetNextItemWidth(-label_room);
  const std::string chosen = st.plot_column >= 0 && st.plot_column < int(tr.columns.size()) ? shown(tr.columns[st.plot_column]) : "(none)";
  if (ImGui::BeginCombo("column", chosen.c_str())) {
    if (ImGui::Selectable("(none)", st.plot_column < 0)) st.plot_column = -1;
    for (int c = 0; c < int(tr.columns.size()); ++c) {
      ImGui::PushID(c);  // two columns may show alike once clipped
      if (ImGui::Selectable(shown(tr.columns[c]).c_str(), c == st.plot_column)) st.plot_column = c;
      ImGui::PopID();
    }
    ImGui::EndCombo();
  }
  tooltip("plot any column of the trace (the same columns as trace_hand.csv)");
}

void metricsSection(TuningSession& session) {
  if (!ImGui::CollapsingHeader("Metrics", ImGuiTreeNodeFlags_DefaultOpen)) return;
  // Recomputed whenever the row on screen changes: the numbers are those of this frame.
  const json& metrics = session.currentMetrics();
  const char* which = !session.problem().empty() ? "up to the stop (a graded run would score 0)"
                      : session.finished()        ? "final, whole run"
                                                  : "running, so far";
  ImGui::TextColored(kMuted, "Lab metrics, %s", which);
  if (!metrics.empty() && ImGui::BeginTable("metrics", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) {
    for (const auto& [key, value] : metrics.items()) {
      ImGui::TableNextRow();
      ImGui::TableSetColumnIndex(0);
      ImGui::TextUnformatted(shown(key).c_str());
      ImGui::TableSetColumnIndex(1);
      const std::string text = value.is_number() ? fmt("%.4g", value.get<double>()) : value.dump();
      ImGui::TextUnformatted(text.c_str());
    }
    ImGui::EndTable();
  }
  if (!session.screening().empty()) {
    ImGui::TextColored(kMuted, "Screening (the loops linearised at the start, as the grader does)");
    for (const std::string& note : session.screening()) {
      const bool bad = note.find("unstable") != std::string::npos || note.find("destabilises") != std::string::npos;
      ImGui::PushStyleColor(ImGuiCol_Text, bad ? kError : ImGui::GetStyleColorVec4(ImGuiCol_Text));
      ImGui::TextWrapped("%s", shown(note, 1000).c_str());
      ImGui::PopStyleColor();
    }
  }
}

void submissionSection(TuningSession& session, PanelState& st) {
  if (!ImGui::CollapsingHeader("Submission", ImGuiTreeNodeFlags_DefaultOpen)) return;
  if (ImGui::Button("Save gains…")) ImGui::OpenPopup("Save gains");
  tooltip("write these gains and options as a submission JSON for dynlab grade");
  if (ImGui::BeginPopupModal("Save gains", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
    ImGui::TextUnformatted("A submission for `dynlab grade` (data only):");
    ImGui::TextColored(kMuted, "%s", session.submission().dump(2).c_str());
    ImGui::SetNextItemWidth(360);
    if (ImGui::IsWindowAppearing()) ImGui::SetKeyboardFocusHere();
    const bool enter = ImGui::InputText("file", &st.save_path, ImGuiInputTextFlags_EnterReturnsTrue);
    if (ImGui::Button("Save", ImVec2(90, 0)) || enter) {
      saveGains(session, st);
      ImGui::CloseCurrentPopup();
    }
    ImGui::SameLine();
    if (ImGui::Button("Cancel", ImVec2(90, 0))) ImGui::CloseCurrentPopup();
    ImGui::EndPopup();
  }
  ImGui::SameLine();
  ImGui::TextColored(kMuted, "%s", shown(st.save_path).c_str());
  if (!st.status.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, st.status_is_error ? kError : kOk);
    ImGui::TextWrapped("%s", shown(st.status, 1000).c_str());
    ImGui::PopStyleColor();
  }
  // The grade hint: the exact command for the saved (or about to be saved) file.
  const std::string file = st.saved_path.empty() ? st.save_path : st.saved_path;
  const std::string command = "dynlab grade " + shellWord(file);
  ImGui::TextColored(kMuted, st.saved_path.empty() ? "Grade, once saved:" : "Grade:");
  ImGui::SameLine();
  ImGui::TextUnformatted(shown(command, 1000).c_str());
  ImGui::SameLine();
  if (ImGui::SmallButton("Copy")) ImGui::SetClipboardText(command.c_str());
  tooltip("copy the command; it writes results.json and report.html into out/grade");
}

}  // namespace

void saveGains(TuningSession& session, PanelState& st) {
  try {
    session.saveSubmission(st.save_path);
    st.saved_path = st.save_path;
    st.status = "Saved " + st.save_path + (st.pending_changes ? " (with gains the current run does not use yet)" : "");
    st.status_is_error = false;
    if (st.saved) st.saved(st.save_path);
  } catch (const std::exception& e) {
    st.status = e.what();
    st.status_is_error = true;
  }
}

void drawTuningPanel(TuningSession& session, PanelState& st, float x, float width, float height) {
  // Shortcuts, unless a text field has the keyboard. (1.86 with the GLFW backend: KeysDown is
  // indexed by GLFW key codes, and GLFW_KEY_R is 'R'.)
  if (!ImGui::GetIO().WantCaptureKeyboard) {
    if (ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Space), false)) st.playing = !st.playing;
    if (ImGui::IsKeyPressed('R', false)) restart(session, st);
  }
  ImGui::SetNextWindowPos(ImVec2(x, 0), ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(width, height), ImGuiCond_Always);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBringToFrontOnFocus;
  // The window's title is the lab's name ("Impedance control", not the whole sentence after it),
  // which fits the panel; the full title is the OS window's.
  const std::string full = session.title(), title = shown(full.substr(0, full.find(": "))) + "###tuning";
  ImGui::Begin(title.c_str(), nullptr, flags);
  // Every name right of its slider in full: the widest one sets the column.
  float widest = ImGui::CalcTextSize("speed").x;
  for (const GainSpec& g : session.gainSpecs()) widest = std::max(widest, ImGui::CalcTextSize(shown(g.name).c_str()).x);
  for (const OptionSpec& o : session.optionSpecs()) widest = std::max(widest, ImGui::CalcTextSize(shown(o.name).c_str()).x);
  label_room = std::min(widest + 2 * ImGui::GetStyle().ItemInnerSpacing.x, 0.45f * width);
  st.widgets.clear();
  st.window_right = x + width;
  ImGui::PushItemWidth(-label_room);
  runSection(session, st);
  problemSection(session);
  ImGui::Spacing();
  // Nothing to tune (a model file's passive run): no gains to set, save or grade.
  const bool tunable = !session.gainSpecs().empty() || !session.optionSpecs().empty();
  if (tunable) gainsSection(session, st);
  else ImGui::TextWrapped("Passive: nothing to tune here. Watch the engines agree, or not.");
  if (!session.notes().empty()) {
    ImGui::TextColored(kMuted, "Notes on the model file");
    for (const std::string& note : session.notes()) ImGui::TextWrapped("%s", shown(note, 1000).c_str());
  }
  plotsSection(session, st);
  metricsSection(session);
  if (tunable) submissionSection(session, st);
  ImGui::PopItemWidth();
  ImGui::End();
}

}  // namespace dyn::ui
