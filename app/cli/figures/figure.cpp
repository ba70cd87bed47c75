// dynlab figure: lecture figures from a lab's run. Plots of trace columns against t, or of one
// column against another (x–y: the path in the plane, equal scales when both axes have one unit;
// grading/plot_curves.h names them), as PDF, SVG or PNG (grading/plot.h; hand solid, Bullet dashed),
// and rendered stills of the scene at chosen times (app/shared/movie.h renderRow through OSMesa; the Bullet
// run as a ghost). Without --plot and --still the lab chooses: the plots its rubric draws (else
// those of its overlay panel that are trace columns), the figures its JSON declares ("figures"),
// and stills at the start, middle and end. Everything is checked before anything is simulated or
// written; output goes through Staging, and a figure run owns DIR/plot_* and DIR/still_*. Under
// --scenario NAME the run is the rubric scenario's, as the grader runs it (commands.h applyScenario).
// Several --gains files are several runs (damper vs spring): every plot overlays them, each curve
// named by its file (grading/plot_curves.h runSeries); stills need one run.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <set>
#include <tuple>

#include "app/cli/commands.h"
#include "app/cli/isolated_draw.h"
#include "app/cli/model/model.h"
#include "app/shared/movie.h"
#include "app/cli/output.h"
#include "app/shared/progress.h"
#include "grading/escape.h"
#include "grading/plot.h"
#include "grading/plot_curves.h"
#include "grading/rubric.h"
#include "grading/student.h"
#include "labs/numbers.h"
#include "labs/run.h"
#include "render/renderer.h"

namespace fs = std::filesystem;

namespace dyn::app {
namespace {

// One plot to draw: its curves (columns against t, or x–y), its title and labels (empty: derived).
struct FigurePlot {
  std::vector<PlotCurve> curves;
  std::string ylabel, xlabel, title;
  std::vector<std::pair<std::string, double>> levels;  // constant levels across (a wall), from "figures"
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

// Adds p unless a plot of the same curves is there already (which `replace` overwrites instead).
void addPlot(std::vector<FigurePlot>& plots, FigurePlot p, bool replace = false) {
  for (auto& q : plots)
    if (q.curves == p.curves) {
      if (replace) q = std::move(p);
      return;
    }
  if (!p.curves.empty()) plots.push_back(std::move(p));
}

// "plot_f_Ty+f_des" against t; "plot_y-vs-x+y_d-vs-x_d" for an x–y plot; "-where-contact" after a masked curve.
std::string fileStem(const std::vector<PlotCurve>& curves) {
  std::vector<std::string> parts;
  for (const auto& c : curves)
    parts.push_back((c.x == "t" ? c.y : c.y + "-vs-" + c.x) + (c.mask.empty() ? "" : "-where-" + c.mask));
  std::string stem = "plot_" + join(parts, "+");
  // A model file with many coordinates (Cassie: 35 q columns) would pass the file system's 255-byte name:
  // the first curve, how many more, and a hash of the whole (FNV-1a) keep it short and distinct.
  if (stem.size() > 120) {
    std::uint32_t h = 2166136261u;
    for (unsigned char ch : stem) h = (h ^ ch) * 16777619u;
    char tail[32];
    std::snprintf(tail, sizeof tail, "+%zu_more_%08x", parts.size() - 1, unsigned(h));
    stem = "plot_" + parts.front().substr(0, 60) + tail;
  }
  return stem;
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
    const PlotRequest& r = *test.plot;
    const std::string x = r.x.empty() ? "t" : r.x, ref_x = r.reference_x.empty() ? x : r.reference_x;
    FigurePlot p{{}, r.ylabel, r.xlabel, ""};
    for (const auto& c : r.columns)
      if (known(c) && (x == "t" || known(x))) p.curves.push_back({c, x, ""});
    if (!r.reference.empty() && known(r.reference) && (ref_x == "t" || known(ref_x))) p.curves.push_back({r.reference, ref_x, ""});
    addPlot(plots, p);
  }
  return plots;
}

// The figures the lab's JSON asks for ("figures"), with their own titles and labels.
std::vector<FigurePlot> declaredPlots(const LoadedLab& loaded) {
  std::vector<FigurePlot> plots;
  for (const LabFigure& f : parseLabFigures(JsonView(loaded.config, loaded.config_file), loaded.lab->columns()))
    addPlot(plots, {f.curves, f.ylabel, f.xlabel, f.title, f.levels});
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
    if (trace.column(name) >= 0) addPlot(plots, {{{name, "t", ""}}, s.name, "", ""});
  }
  return plots;
}

// A requested plot with the lab's own labels and levels for exactly these curves (from its
// "figures", else its rubric); without any, fillLabels derives them from the columns.
FigurePlot labelled(const std::vector<PlotCurve>& curves, const std::vector<FigurePlot>& lab_plots) {
  const auto key = [](const std::vector<PlotCurve>& cs) {
    std::set<std::tuple<std::string, std::string, std::string>> k;
    for (const auto& c : cs) k.insert({c.y, c.x, c.mask});
    return k;
  };
  FigurePlot p{curves, "", "", ""};
  for (const auto& q : lab_plots)
    if (key(q.curves) == key(curves)) {
      p.ylabel = q.ylabel, p.xlabel = q.xlabel, p.levels = q.levels;
      break;
    }
  return p;
}

// The labels a plot is drawn with: its own, else its columns with their units (x: t in seconds).
void fillLabels(const Lab& lab, FigurePlot& p) {
  if (p.ylabel.empty()) p.ylabel = axisLabel(lab, yColumns(p.curves));
  if (p.xlabel.empty()) p.xlabel = parametric(p.curves) ? axisLabel(lab, xColumns(p.curves)) : "t (s)";
}

// One plot of the runs: runSeries's curves (hand solid, Bullet dashed; each run named when there are
// several). An x–y plot is linear, with equal scales when its axes have one unit (metres against metres).
PlotSpec plotSpec(const Lab& lab, const FigurePlot& p, const std::string& title, const std::vector<PlotRun>& runs,
                  const FigureArgs& a) {
  PlotSpec spec;
  spec.title = title;
  spec.font_scale = a.font_scale;
  spec.y_scale = a.y_scale == "log" ? YScale::Log : a.y_scale == "linear" ? YScale::Linear : YScale::Auto;
  spec.xlabel = p.xlabel;
  spec.ylabel = p.ylabel;
  spec.parametric = parametric(p.curves);
  spec.equal_aspect = spec.parametric && sameUnit(lab, xColumns(p.curves), yColumns(p.curves));
  spec.series = runSeries(p.curves, runs);
  // Levels across the run's time (a plot against t), dashed black (the palette's last colour).
  const Trace* first = runs.empty() ? nullptr : runs.front().hand ? runs.front().hand : runs.front().bullet;
  if (!spec.parametric && first && first->rows() > 1) {
    const double t0 = first->at(0, "t"), t1 = first->at(first->rows() - 1, "t");
    for (const auto& [label, y] : p.levels) spec.series.push_back({label, {t0, t1}, {y, y}, PlotSeries::Style::Dashed, 6});
  }
  return spec;
}

// A gains file in a legend: its last component, terminal-safe, at most 32 bytes; the path as given
// when another run's file has the same name.
std::string runName(const std::vector<std::string>& files, std::size_t i) {
  const auto base = [](const std::string& f) { return fs::path(f).filename().string(); };
  std::string s = base(files[i]);
  for (std::size_t j = 0; j < files.size(); ++j)
    if (j != i && base(files[j]) == s) s = files[i];
  s = termText(s);
  if (s.size() <= 32) return s;
  std::size_t cut = s.size() - 31;
  while (cut < s.size() && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) ++cut;  // not inside a character
  return "…" + s.substr(cut);
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

// What the command line asks for, checked before anything is simulated or written.
struct FigureRequest {
  std::vector<LoadedLab> loads;  // one per gains file (none given: the lab's own gains)
  std::pair<int, int> size{1920, 1080}, plot_size{800, 450};
  std::vector<double> stills;
  std::vector<FigurePlot> declared, plots;
  bool own_set = false;  // neither --plot nor --still: the lab's plots and stills
};

// The options each checked (--format, --size, each --gains file once, one run for stills).
void checkOptions(const FigureArgs& a, FigureRequest& q) {
  if (a.format != "pdf" && a.format != "svg" && a.format != "png") badOption("--format", a.format, "expected pdf, svg or png");
  // One --size for stills and plots (a plot needs at least 100x100 for its labels).
  if (!a.size.empty()) {
    q.size = q.plot_size = parseSize(a.size);
    const bool draws_plots = !a.plots.empty() || a.stills.empty();  // the lab's own set has plots
    if (draws_plots && (q.size.first < 100 || q.size.second < 100)) badOption("--size", a.size, "expected at least 100x100 for a plot");
  }
  // Each gains file once (the same file twice, however spelled, is a mistake); several: no stills.
  std::set<fs::path> seen;
  for (const auto& g : a.gains) {
    std::error_code ec;
    const fs::path key = fs::weakly_canonical(fs::path(g), ec);
    if (!seen.insert(ec ? fs::path(g) : key).second) badOption("--gains", g, "expected each gains file once (it is given twice)");
  }
  if (a.gains.size() > 1 && !a.stills.empty())
    badOption("--still", fmt("%g", a.stills.front()), "expected one --gains file with --still (a still shows one run)");
}

// The lab (or model file) loaded once per gains file, under the scenario.
void loadRuns(const FigureArgs& a, FigureRequest& q) {
  if (isModelFile(a.lab)) {
    // A model file where a lab goes: its passive run (app/cli/model/model.h loadModelLab); no gains, scenario or config.
    const std::string gains = a.gains.empty() ? "" : a.gains.front();
    for (const auto& [option, value] : {std::pair{"--gains", gains}, {"--scenario", a.scenario}, {"--config", a.config}})
      if (!value.empty()) badOption(option, value, "a model file runs passive: it has no gains, scenarios or lab config");
    q.loads.push_back(loadModelLab(a.lab, a.duration, a.model_files));
    return;
  }
  const std::vector<std::string> gains_files = a.gains.empty() ? std::vector<std::string>{""} : a.gains;
  for (const auto& g : gains_files) {
    q.loads.push_back(loadLab(a.lab, a.config, g, a.duration, studentPlant(a.student)));
    applyScenario(q.loads.back(), a.scenario, a.duration);
  }
}

// The request checked: options, the runs loaded, the plots and stills within the run. Throws InputError.
FigureRequest checkRequest(const FigureArgs& a) {
  FigureRequest q;
  q.stills = a.stills;
  checkOptions(a, q);
  loadRuns(a, q);
  const LoadedLab& loaded = q.loads.front();
  std::vector<std::vector<PlotCurve>> requested;
  for (const auto& spec : a.plots) requested.push_back(parsePlotCurves(spec, loaded.lab->columns(), "<command line>", "--plot " + spec));
  const double duration = loaded.lab->duration();
  if (duration < loaded.lab->dt())  // a figure of a run needs at least one step of it
    badOption("--duration", exactNumber(duration), "expected at least one step (dt = " + fmt("%g", loaded.lab->dt()) + " s)");
  if (double(q.stills.size()) > kMaxFrames)  // the frames a run may draw (labs/settings.h)
    badOption("--still", fmt("%g", q.stills.back()), std::to_string(q.stills.size()) + " stills are more than the " +
                                                         fmt("%g", kMaxFrames) + " frames a run may draw");
  for (double t : q.stills)
    if (!(t >= 0 && t <= duration))
      badOption("--still", exactNumber(t), "expected a time in [0, " + fmt("%g", duration) + "] s (the run's duration)");
  const std::vector<FigurePlot> rubric_plots = rubricPlots(loaded);
  q.declared = declaredPlots(loaded);
  std::vector<FigurePlot> known = q.declared;  // a declared figure's labels first: they are for figures
  known.insert(known.end(), rubric_plots.begin(), rubric_plots.end());
  for (const auto& curves : requested) q.plots.push_back(labelled(curves, known));
  q.own_set = a.plots.empty() && q.stills.empty();
  if (q.own_set) {
    if (q.loads.size() == 1) q.stills = {0.0, 0.5 * duration, duration};
    q.plots = rubric_plots;
  }
  return q;
}

// Each gains file's runs (in the order given), with a bar on a terminal; the first one's are the stills'.
struct FigureRuns {
  std::vector<std::optional<RunResult>> hands, bullets;
  std::vector<PlotRun> runs;
  const RunResult& shown() const { return hands.front() ? *hands.front() : *bullets.front(); }
  // "ok", or the last run that failed and why.
  std::string status() const {
    std::string status = "ok";
    for (std::size_t i = 0; i < hands.size(); ++i)
      for (const auto* r : {&hands[i], &bullets[i]})
        if (*r && !(*r)->failure.empty())
          status = (runs[i].name.empty() ? "" : runs[i].name + ", ") + (r == &hands[i] ? "hand" : "bullet") + ": " + (*r)->failure;
    return status;
  }
};

void simulate(const FigureArgs& a, const std::vector<LoadedLab>& loads, FigureRuns& f) {
  auto run = [&](const Lab& l, Engine engine) {
    Progress bar(std::string("simulating ") + (engine == Engine::Hand ? "hand" : "Bullet"),
                 std::size_t(std::max(1L, std::lround(l.duration() / l.dt()))));
    return runEngine(l, engine, -1, [&](long steps) { bar.set(std::size_t(steps)); });
  };
  f.hands.resize(loads.size());
  f.bullets.resize(loads.size());
  for (std::size_t i = 0; i < loads.size(); ++i) {
    if (a.engine != "bullet") f.hands[i] = run(*loads[i].lab, Engine::Hand);
    if (a.engine != "hand") f.bullets[i] = run(*loads[i].lab, Engine::Bullet);
  }
  for (std::size_t i = 0; i < loads.size(); ++i)
    f.runs.push_back({loads.size() > 1 ? runName(a.gains, i) : "", f.hands[i] ? &f.hands[i]->trace : nullptr,
                      f.bullets[i] ? &f.bullets[i]->trace : nullptr});
}

// What a figure run wrote, and what it did not and why.
struct Written {
  std::vector<std::string> files, skipped;
  std::set<std::string> names;  // each file's name once
};

// The plots, each drawn in a child (PLplot's cairo driver ends the process when memory runs out).
void writePlots(const FigureArgs& a, const Lab& lab, const FigureRequest& q, const FigureRuns& f, const std::string& lab_title,
                Staging& staging, Progress& bar, Written& w) {
  std::size_t made = 0;
  for (const FigurePlot& p : q.plots) {
    const std::string name = fileStem(p.curves) + "." + a.format;
    bar.set(made++);
    if (!w.names.insert(name).second) continue;
    const std::string title = !a.title.empty() ? a.title : lab_title + ": " + (p.title.empty() ? curvesText(p.curves) : p.title);
    const PlotSpec spec = plotSpec(lab, p, title, f.runs, a);
    // Masks that are 0 all run long leave nothing to draw: said, never an empty picture.
    const auto drawn = [](const PlotSeries& ser) {
      for (std::size_t i = 0; i < ser.x.size(); ++i)
        if (std::isfinite(ser.x[i]) && std::isfinite(ser.y[i])) return true;
      return false;
    };
    const bool masked = std::any_of(p.curves.begin(), p.curves.end(), [](const PlotCurve& c) { return !c.mask.empty(); });
    if (masked && std::none_of(spec.series.begin(), spec.series.end(), drawn)) {
      w.skipped.push_back(name + " (" + curvesText(p.curves) + ": nothing to draw, its masks are 0 throughout)");
      continue;
    }
    drawIsolated(name, [&] { writePlot(staging.path(name).string(), spec, q.plot_size.first, q.plot_size.second); });
    w.files.push_back(name);
  }
}

// The stills of the first run, each name once, drawn in a child (OSMesa's llvmpipe aborts when memory runs out).
void writeStills(const FigureArgs& a, const Lab& lab, const FigureRequest& q, const FigureRuns& f, Staging& staging,
                 Progress& bar, Written& w) {
  std::vector<std::pair<double, std::string>> todo;
  for (double t : q.stills)
    if (const std::string name = "still_" + fmt("%.3f", t + 0.0) + ".png"; w.names.insert(name).second)  // + 0.0: no "-0.000"
      todo.push_back({t, name});
  const std::optional<RunResult>& hand = f.hands.front();
  const std::optional<RunResult>& bullet = f.bullets.front();
  const RunResult& shown = f.shown();
  drawIsolated(todo.size() == 1 ? todo.front().second : "the stills", [&] {
    auto context = makeOffscreenContext(q.size.first, q.size.second);
    RenderOptions options;
    options.show_overlay = a.overlay;
    Renderer renderer(*context, options);
    const Trace* ghost = hand && bullet ? &bullet->trace : nullptr;
    for (std::size_t i = 0; i < todo.size(); ++i) {
      bar.set(q.plots.size() + i);
      const std::size_t row = rowAt(shown.trace, lab.dt(), todo[i].first);
      const Image image = renderRow(renderer, lab, shown.trace, row, ghost, a.overlay, a.title);
      if (std::string why; !writePng(staging.path(todo[i].second).string(), image, &why)) throw std::runtime_error(why);
    }
  });
  for (const auto& still : todo) w.files.push_back(still.second);
}

// The report: the run, each file written, what was not and why, and an earlier run's figures now gone.
void printWritten(const FigureArgs& a, const Lab& lab, const std::string& status, const fs::path& out, const Written& w,
            const std::vector<std::string>& earlier) {
  std::printf("dynlab figure %s: %.2f s at dt = %g s, engine %s (%s)\n",
              termText(a.scenario.empty() ? a.lab : a.lab + " (" + a.scenario + ")").c_str(), lab.duration(), lab.dt(),
              a.engine.c_str(), status.c_str());
  for (const auto& name : w.files) std::printf("  %s\n", (out / name).c_str());
  for (const auto& why : w.skipped) std::printf("  not written: %s\n", termText(why).c_str());
  // An earlier figure run's figures this one did not remake are gone: said, never silent.
  std::string removed;
  for (const auto& name : earlier)
    if (std::find(w.files.begin(), w.files.end(), name) == w.files.end()) removed += (removed.empty() ? "" : ", ") + name;
  if (!removed.empty())
    std::printf("  removed the earlier figure run's %s (use another --out to keep figures side by side)\n", termText(removed).c_str());
}

}  // namespace

int figure(const FigureArgs& a) {
  FigureRequest q;
  try {
    q = checkRequest(a);  // every input checked before simulating or writing anything
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", termText(e.what()).c_str());
    return 2;
  }
  const Lab& lab = *q.loads.front().lab;
  const fs::path out = a.out.empty() ? defaultOut(a.lab, a.scenario, "figures") : fs::path(a.out);
  // Titles name the lab as its handout does ("Impedance control"), not by its id.
  const std::string shown = labDisplayName(q.loads.front().config, a.lab);
  const std::string lab_title = a.scenario.empty() ? shown : shown + " (" + a.scenario + ")";
  try {
    FigureRuns f;
    simulate(a, q.loads, f);
    // The lab's own set: its rubric's plots (else its overlay's), then the figures it declares
    // (one of the same curves as a rubric plot takes its place, with its title and labels).
    if (q.own_set) {
      if (q.plots.empty()) q.plots = overlayPlots(lab, f.shown().trace);
      for (const auto& p : q.declared) addPlot(q.plots, p, true);
    }
    for (auto& p : q.plots) fillLabels(lab, p);

    Staging staging(out);
    const std::vector<std::string> earlier = ownedFigures(out);
    staging.owns(earlier);
    Written w;
    Progress bar("figures", q.plots.size() + q.stills.size());
    writePlots(a, lab, q, f, lab_title, staging, bar, w);
    if (!q.stills.empty()) writeStills(a, lab, q, f, staging, bar, w);
    bar.set(q.plots.size() + q.stills.size());
    bar.done();
    staging.commit();
    const std::string status = f.status();
    printWritten(a, lab, status, out, w, earlier);
    return status == "ok" ? 0 : 1;
  } catch (const std::bad_alloc&) {
    throw;  // main's one line for it (app/cli/main.cpp)
  } catch (const InputError& e) {  // found only once a run starts (a model file Bullet cannot build): bad input
    std::fprintf(stderr, "error: %s\n", termText(e.what()).c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", termText(e.what()).c_str());
    return 1;
  }
}

}  // namespace dyn::app
