// dynlab figure: lecture figures from a lab's run. Plots of trace columns against t (grading/plot.h:
// PDF, SVG or PNG; hand solid, Bullet dashed) and rendered stills of the scene at chosen times
// (app/movie.h renderRow through OSMesa; the Bullet run as a ghost). Without --plot and --still the
// lab chooses: the plots its rubric draws (else those of its overlay panel that are trace columns)
// and stills at the start, middle and end. Everything is checked before anything is simulated or
// written; output goes through Staging, and a figure run owns DIR/plot_* and DIR/still_*. Under
// --scenario NAME the run is the rubric scenario's, as the grader runs it (commands.h applyScenario).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>

#include "app/commands.h"
#include "app/movie.h"
#include "app/output.h"
#include "app/progress.h"
#include "grading/escape.h"
#include "grading/plot.h"
#include "grading/rubric.h"
#include "labs/numbers.h"
#include "labs/run.h"
#include "render/renderer.h"

namespace fs = std::filesystem;

namespace dyn::app {
namespace {

// One plot to draw: trace columns against t, and its y label (empty: the column names).
struct FigurePlot {
  std::vector<std::string> columns;
  std::string ylabel;
};

// Bad command-line input: "<command line>: OPTION VALUE: expected ...", exit code 2.
[[noreturn]] void badOption(const std::string& option, const std::string& value, const std::string& expected) {
  throw InputError("<command line>", option + " " + value, expected);
}

std::string join(const std::vector<std::string>& parts, const std::string& sep) {
  std::string s;
  for (const auto& p : parts) s += (s.empty() ? "" : sep) + p;
  return s;
}

// "1920x1080" → {1920, 1080}.
std::pair<int, int> parseSize(const std::string& s) {
  int w = 0, h = 0;
  if (!parseFrameSize(s, 16, 16, w, h))
    badOption("--size", s, "expected WIDTHxHEIGHT in pixels, each 16 to 8192 (e.g. 1920x1080)");
  return {w, h};
}

// "theta, theta_d" → {"theta", "theta_d"}, every name a column of the lab.
std::vector<std::string> parseColumns(const std::string& spec, const std::vector<std::string>& columns) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= spec.size()) {
    std::size_t end = spec.find(',', start);
    if (end == std::string::npos) end = spec.size();
    std::string name = spec.substr(start, end - start);
    name.erase(0, name.find_first_not_of(' '));
    name.erase(name.find_last_not_of(' ') + 1);
    if (std::find(columns.begin(), columns.end(), name) == columns.end())
      badOption("--plot", spec,
                (name.empty() ? std::string("empty column name") : "unknown column \"" + name + "\"") +
                    "; expected trace columns separated by commas, one of: " + join(columns, ", "));
    if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
    start = end + 1;
  }
  return out;
}

void addPlot(std::vector<FigurePlot>& plots, FigurePlot p) {
  for (const auto& q : plots)
    if (q.columns == p.columns) return;
  if (!p.columns.empty()) plots.push_back(std::move(p));
}

// The plots the lab's rubric draws (each response with its reference), with the rubric's y label
// and its unit: the Lab interface declares no units of its own. Throws InputError on a bad rubric.
std::vector<FigurePlot> rubricPlots(const LoadedLab& loaded) {
  std::vector<FigurePlot> plots;
  if (!loaded.config.contains("rubric")) return plots;
  const std::vector<std::string> columns = loaded.lab->columns();
  auto known = [&](const std::string& c) { return std::find(columns.begin(), columns.end(), c) != columns.end(); };
  for (const RubricTest& test : parseRubric(JsonView(loaded.config, loaded.config_file)).tests) {
    if (!test.plot) continue;
    FigurePlot p{{}, test.plot->ylabel};
    for (const auto& c : test.plot->columns)
      if (known(c)) p.columns.push_back(c);
    if (!test.plot->reference.empty() && known(test.plot->reference)) p.columns.push_back(test.plot->reference);
    addPlot(plots, p);
  }
  return plots;
}

// A lab without rubric plots: the overlay panel's series that are trace columns ("tau (N·m)").
std::vector<FigurePlot> overlayPlots(const Lab& lab, const Trace& trace) {
  std::vector<FigurePlot> plots;
  if (trace.rows() == 0) return plots;
  Overlay overlay;
  lab.overlay(trace, 0, overlay);
  for (const Series& s : overlay.plots) {
    const std::string name = s.name.substr(0, s.name.find(" ("));
    if (trace.column(name) >= 0) addPlot(plots, {{name}, s.name});
  }
  return plots;
}

// The y label of a requested plot: the lab's own label for exactly these columns (from its
// rubric), else the column names with the lab's units ("theta, theta_d (rad)"; "x (m), theta (rad)").
std::string ylabelFor(const Lab& lab, const std::vector<std::string>& columns,
                      const std::vector<FigurePlot>& lab_plots) {
  for (const auto& p : lab_plots)
    if (std::set<std::string>(p.columns.begin(), p.columns.end()) ==
        std::set<std::string>(columns.begin(), columns.end()))
      return p.ylabel;
  std::set<std::string> units;
  for (const auto& c : columns) units.insert(lab.unit(c));
  if (units.size() == 1) {
    const std::string& u = *units.begin();
    return join(columns, ", ") + (u.empty() ? "" : " (" + u + ")");
  }
  std::vector<std::string> labelled;
  for (const auto& c : columns) labelled.push_back(lab.unit(c).empty() ? c : c + " (" + lab.unit(c) + ")");
  return join(labelled, ", ");
}

// One plot of the runs: each column a colour, hand solid and Bullet dashed; a column the engines
// share exactly (a reference, a setpoint) is drawn once, as both engines'.
PlotSpec plotSpec(const FigurePlot& p, const std::string& title, const RunResult* hand, const RunResult* bullet,
                  const FigureArgs& a) {
  PlotSpec spec;
  spec.title = title;
  spec.font_scale = a.font_scale;
  spec.y_scale = a.y_scale == "log" ? YScale::Log : a.y_scale == "linear" ? YScale::Linear : YScale::Auto;
  spec.xlabel = "t (s)";
  spec.ylabel = p.ylabel.empty() ? join(p.columns, ", ") : p.ylabel;
  for (std::size_t k = 0; k < p.columns.size(); ++k) {
    const std::string& c = p.columns[k];
    const std::vector<double> h = hand ? hand->trace.series(c) : std::vector<double>{};
    const std::vector<double> b = bullet ? bullet->trace.series(c) : std::vector<double>{};
    if (hand && bullet && h == b) {
      spec.series.push_back({c + " (hand, Bullet)", hand->trace.series("t"), h, PlotSeries::Style::Solid, int(k)});
      continue;
    }
    if (hand) spec.series.push_back({c + " (hand)", hand->trace.series("t"), h, PlotSeries::Style::Solid, int(k)});
    if (bullet) spec.series.push_back({c + " (Bullet)", bullet->trace.series("t"), b, PlotSeries::Style::Dashed, int(k)});
  }
  return spec;
}

// A figure run owns what an earlier one may have left: DIR/plot_*.{pdf,svg,png} and DIR/still_*.png.
std::vector<std::string> ownedFigures(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string(), ext = e.path().extension().string();
    if ((name.rfind("plot_", 0) == 0 && (ext == ".pdf" || ext == ".svg" || ext == ".png")) ||
        (name.rfind("still_", 0) == 0 && ext == ".png"))
      names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

int figure(const FigureArgs& a) {
  // Check every input before simulating or writing anything.
  LoadedLab loaded;
  std::pair<int, int> size{1920, 1080}, plot_size{800, 450};
  std::vector<std::vector<std::string>> requested;
  std::vector<double> stills = a.stills;
  std::vector<FigurePlot> lab_plots, plots;
  try {
    if (a.format != "pdf" && a.format != "svg" && a.format != "png")
      badOption("--format", a.format, "expected pdf, svg or png");
    // One --size for stills and plots (a plot needs at least 100x100 for its labels).
    if (!a.size.empty()) {
      size = plot_size = parseSize(a.size);
      const bool draws_plots = !a.plots.empty() || a.stills.empty();  // the lab's own set has plots
      if (draws_plots && (size.first < 100 || size.second < 100))
        badOption("--size", a.size, "expected at least 100x100 for a plot");
    }
    loaded = loadLab(a.lab, a.config, a.gains, a.duration);
    applyScenario(loaded, a.scenario, a.gains, a.duration);
    const std::vector<std::string> columns = loaded.lab->columns();
    for (const auto& spec : a.plots) requested.push_back(parseColumns(spec, columns));
    const double duration = loaded.lab->duration();
    for (double t : stills)
      if (!(t >= 0 && t <= duration))
        badOption("--still", fmt("%g", t), "expected a time in [0, " + fmt("%g", duration) + "] s (the run's duration)");
    lab_plots = rubricPlots(loaded);
    for (const auto& cols : requested) plots.push_back({cols, ylabelFor(*loaded.lab, cols, lab_plots)});
    if (a.plots.empty() && stills.empty()) {
      stills = {0.0, 0.5 * duration, duration};
      plots = lab_plots;
    }
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", termText(e.what()).c_str());
    return 2;
  }
  const Lab& lab = *loaded.lab;
  const fs::path out = a.out.empty() ? defaultOut(a.lab, a.scenario, "figures") : fs::path(a.out);
  const std::string lab_title = a.scenario.empty() ? a.lab : a.lab + " (" + a.scenario + ")";
  try {
    // A bar on a terminal for each stage (nothing otherwise): the runs, then the figures.
    auto run = [&](Engine engine) {
      Progress bar(std::string("simulating ") + (engine == Engine::Hand ? "hand" : "Bullet"),
                   std::size_t(std::max(1L, std::lround(lab.duration() / lab.dt()))));
      return runEngine(lab, engine, -1, [&](long steps) { bar.set(std::size_t(steps)); });
    };
    std::optional<RunResult> hand, bullet;
    if (a.engine != "bullet") hand = run(Engine::Hand);
    if (a.engine != "hand") bullet = run(Engine::Bullet);
    const RunResult& shown = hand ? *hand : *bullet;

    if (a.plots.empty() && a.stills.empty() && plots.empty()) plots = overlayPlots(lab, shown.trace);

    Staging staging(out);
    const std::vector<std::string> earlier = ownedFigures(out);
    staging.owns(earlier);
    std::vector<std::string> written;
    std::set<std::string> names;
    Progress bar("figures", plots.size() + stills.size());
    std::size_t made = 0;
    for (const FigurePlot& p : plots) {
      const std::string name = "plot_" + join(p.columns, "+") + "." + a.format;
      bar.set(made++);
      if (!names.insert(name).second) continue;
      const std::string title = a.title.empty() ? lab_title + ": " + join(p.columns, ", ") : a.title;
      writePlot(staging.path(name).string(), plotSpec(p, title, hand ? &*hand : nullptr, bullet ? &*bullet : nullptr, a),
                plot_size.first, plot_size.second);
      written.push_back(name);
    }
    if (!stills.empty()) {
      auto context = makeOffscreenContext(size.first, size.second);
      RenderOptions options;
      options.show_overlay = a.overlay;
      Renderer renderer(*context, options);
      const Trace* ghost = hand && bullet ? &bullet->trace : nullptr;
      for (double t : stills) {
        const std::string name = "still_" + fmt("%.3f", t + 0.0) + ".png";  // + 0.0: no "-0.000"
        bar.set(made++);
        if (!names.insert(name).second) continue;
        const std::size_t row = rowAt(shown.trace, lab.dt(), t);
        const Image image = renderRow(renderer, lab, shown.trace, row, ghost, a.overlay, a.title);
        if (std::string why; !writePng(staging.path(name).string(), image, &why)) throw std::runtime_error(why);
        written.push_back(name);
      }
    }
    bar.set(made);
    bar.done();
    staging.commit();

    std::string status = "ok";
    for (const auto* r : {&hand, &bullet})
      if (*r && !(*r)->failure.empty()) status = std::string(r == &hand ? "hand" : "bullet") + ": " + (*r)->failure;
    std::printf("dynlab figure %s: %.2f s at dt = %g s, engine %s (%s)\n", termText(lab_title).c_str(), lab.duration(),
                lab.dt(), a.engine.c_str(), status.c_str());
    for (const auto& name : written) std::printf("  %s\n", (out / name).c_str());
    // An earlier figure run's figures this one did not remake are gone: said, never silent.
    std::string removed;
    for (const auto& name : earlier)
      if (std::find(written.begin(), written.end(), name) == written.end()) removed += (removed.empty() ? "" : ", ") + name;
    if (!removed.empty())
      std::printf("  removed the earlier figure run's %s (use another --out to keep figures side by side)\n", termText(removed).c_str());
    return status == "ok" ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", termText(e.what()).c_str());
    return 1;
  }
}

}  // namespace dyn::app
