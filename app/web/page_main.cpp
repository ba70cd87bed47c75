// dynlab.js: the page (build/web/index.html) — dynlab-ui's tuning window in a WebGL 2 canvas. The
// same session, frame and panel code as the native window (app/ui: frame.h, panel.h, session.h),
// over emscripten's GLFW; the browser drives the frames (emscripten_set_main_loop). index.html reads
// the link (?lab=NAME&gains=…&grade=1) and starts the program with
//   LAB [--size WxH] [--gains FILE] [--grade] [--bench] [--probe]
// (FILE written into the page's memory file system first). What the page's buttons call (grade,
// handout, upload) is in page_api.cpp. The model-file labs read their models' exported descriptions
// (/dynlab/models in dynlab.data, docs/web.md "Model descriptions").
#include "app/web/page.h"

#include <emscripten.h>
#include <imgui.h>

#include <GLFW/glfw3.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "labs/generic/lab_folders.h"
#include "labs/generic/model_description.h"
#include "labs/utf8.h"

namespace dyn::web {
namespace {

Page* g_page = nullptr;

// Offers a file of the memory file system to the browser as a download (its base name).
EM_JS(void, offerDownload, (const char* path), {
  const p = UTF8ToString(path);
  const data = FS.readFile(p);
  const a = document.createElement('a');
  a.href = URL.createObjectURL(new Blob([data], {type: 'application/json'}));
  a.download = p.substring(p.lastIndexOf('/') + 1);
  document.body.appendChild(a);
  a.click();
  a.remove();
});

// Milliseconds since the page's navigation began (the page clock).
EM_JS(double, pageClockMs, (), { return performance.now(); });

// How far the hand engine and the Bullet ghost are apart at the shown row: the largest difference
// of a joint coordinate (columns named q…) both traces have.
std::string agreement(const ui::TuningSession& s) {
  const Trace* ghost = s.ghost();
  if (!ghost || !s.hasRows()) return "";
  const Trace& hand = s.primary();
  const std::size_t row = std::min(s.row(), ghost->rows() ? ghost->rows() - 1 : 0);
  if (ghost->rows() == 0) return "";
  double worst = 0;
  std::string where;
  for (std::size_t c = 0; c < hand.columns.size(); ++c) {
    const std::string& name = hand.columns[c];
    const int g = ghost->column(name);
    if (name.empty() || name[0] != 'q' || g < 0) continue;
    const double d = std::abs(hand.at(row, int(c)) - ghost->at(row, g));
    if (d >= worst) worst = d, where = name;
  }
  if (where.empty()) return "";
  char text[160];
  std::snprintf(text, sizeof text, "hand vs Bullet ghost at t = %.2f s: max |Δq| = %.3g (%s)", ghost->at(row, 0), worst,
                termName(where, 40).c_str());
  return text;
}

// The agreement readout in the bottom-left corner of the scene.
void drawAgreement(const ui::TuningSession& s, const ui::Layout& l) {
  const std::string text = agreement(s);
  if (text.empty()) return;
  const float scale = std::max(ImGui::GetIO().DisplayFramebufferScale.x, 1e-3f);
  const ImVec2 at(12.0f, float(l.scene_h) / scale - ImGui::GetFontSize() - 10.0f);
  const ImVec2 size = ImGui::CalcTextSize(text.c_str());
  ImDrawList* draw = ImGui::GetBackgroundDrawList();
  draw->AddRectFilled(ImVec2(at.x - 6, at.y - 3), ImVec2(at.x + size.x + 6, at.y + size.y + 3), IM_COL32(255, 255, 255, 215), 3.0f);
  draw->AddText(at, IM_COL32(30, 40, 55, 255), text.c_str());
}

// Counts the scene's pixels that differ from its background (the colour at the scene's top-left
// corner): 0 when nothing was drawn. Reads the canvas inside the frame, before the browser shows it.
long drawnPixels(const WindowContext& ctx, const ui::Layout& l) {
  const Image shot = ctx.screenshot();
  if (l.scene_w <= 0 || l.scene_h <= 0) return 0;
  auto px = [&](int x, int y) { return &shot.rgba[(std::size_t(y) * shot.width + x) * 4]; };
  const std::uint8_t* bg = px(l.scene_x, l.scene_y);
  long n = 0;
  for (int y = l.scene_y; y < l.scene_y + l.scene_h && y < shot.height; ++y)
    for (int x = l.scene_x; x < l.scene_x + l.scene_w && x < shot.width; ++x) {
      const std::uint8_t* p = px(x, y);
      n += p[0] != bg[0] || p[1] != bg[1] || p[2] != bg[2];
    }
  return n;
}

void frame() {
  Page& p = *g_page;
  glfwPollEvents();
  const double now = p.ctx->seconds();
  const double wall = std::clamp(now - p.last, 0.0, 0.1);
  p.last = now;
  if (p.session) p.tuning.advance(*p.session, p.st, wall);
  ui::Layout l;
  if (p.session) {
    l = p.tuning.draw(*p.session, p.st, *p.ctx, [&](const ui::Layout& shown) { drawAgreement(*p.session, shown); });
  } else {
    p.ctx->clear(Color{0.93f, 0.94f, 0.95f, 1.0f});
  }
  ++p.frames;
  if (p.frames == 1) std::printf("dynlab first frame: %.0f ms after navigation start\n", pageClockMs());
  // The probe (tests/web): after a few frames, how much of the scene was drawn.
  if (p.probe && p.frames == 5)
    std::printf("dynlab canvas: %s %ld of %d scene pixels drawn (%dx%d canvas)\n", p.lab.c_str(), drawnPixels(*p.ctx, l),
                l.scene_w * l.scene_h, p.ctx->width(), p.ctx->height());
}

}  // namespace

Page& page() { return *g_page; }

void useSession(std::unique_ptr<ui::TuningSession> session) {
  Page& p = *g_page;
  p.tuning.release();
  p.session = std::move(session);
  p.session->setEngine(ui::EngineChoice::Both);
  p.session->restart();
  p.st.saved_path.clear();
  p.st.status.clear();
}

}  // namespace dyn::web

int main(int argc, char** argv) {
  using namespace dyn;
  using namespace dyn::web;
  static Page p;
  g_page = &p;
  std::vector<std::string> args(argv + 1, argv + argc);
  p.lab = args.empty() ? "slider_crank" : args[0];
  std::string gains;
  int width = 1320, height = 720;
  for (std::size_t i = 1; i < args.size(); ++i) {
    if (args[i] == "--gains" && i + 1 < args.size()) gains = args[++i];
    else if (args[i] == "--size" && i + 1 < args.size()) {
      // The browser window's size, from index.html: within what the panel and the scene need.
      if (std::sscanf(args[++i].c_str(), "%dx%d", &width, &height) != 2) width = 1320, height = 720;
      width = std::clamp(width, 800, 4096), height = std::clamp(height, 480, 4096);
    } else if (args[i] == "--grade") p.grade_at_load = true;
    else if (args[i] == "--bench") p.bench = true;
    else if (args[i] == "--probe") p.probe = true;
  }
  generic::useLabsFolders({});
  // The model-file labs (fivebar, puma_*): no MuJoCo parser here, their models' descriptions instead,
  // exported by scripts/web and packed into dynlab.data (FOLDER/REL.json for the model file at /dynlab/REL).
  app::setDescriptionsFolder("/dynlab/models");
  p.st.save_path = p.lab + "_gains.json";  // the memory file system's; offered as a download once written
  p.st.saved = [](const std::string& path) { offerDownload(path.c_str()); };
  p.load_error = openLab(p.lab, gains);
  if (!p.load_error.empty()) std::printf("dynlab page: %s\n", p.load_error.c_str());
  if (p.bench && p.session) benchmark(*p.session);
  // The link's submission as it was given (not re-written by the session): the grade a staff member
  // sees for "open this submission", a refused one included (its results.json says why, as dynlab grade's).
  if (p.grade_at_load && (!gains.empty() || p.session)) gradeAndPrint(gains);
  try {
    p.ctx = makeWindowContext({width, height, "dynlab", true});
    ui::setupImGui(p.ctx->window(), *p.ctx);
  } catch (const std::exception& e) {
    std::printf("dynlab page: error: %s\n", e.what());
    return 1;
  }
  p.last = p.ctx->seconds();
  emscripten_set_main_loop(frame, 0, false);
  return 0;
}
