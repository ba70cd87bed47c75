// Screening and watched runs of one scenario; see scenario.h.
#include "grading/scenario.h"

#include <cmath>
#include <cstdio>

namespace dyn {

std::string fmtNumber(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", x);
  return b;
}

namespace {

std::string fmtMs(double s) { return s >= kUnboundedDelay ? "unbounded" : fmtNumber(s * 1e3) + " ms"; }

std::string fmtPole(std::complex<double> p) {
  std::string s = (p.real() >= 0 ? "+" : "") + fmtNumber(p.real());
  if (std::abs(p.imag()) > 1e-9) s += " ± " + fmtNumber(std::abs(p.imag())) + "j";
  return s + " rad/s";
}

}  // namespace

ScreenResult screenLoops(const Lab& lab) {
  ScreenResult r;
  for (const LinearLoop& loop : lab.linearise()) {
    const LoopAnalysis a = analyseLoop(loop);
    const std::string& n = loop.name;
    r.metrics[n + "_max_real_pole"] = a.max_real;
    r.metrics[n + "_damping"] = a.min_damping;
    r.metrics[n + "_delay_margin"] = a.delay_margin;
    r.metrics[n + "_phase_margin_deg"] = a.phase_margin * 180.0 / M_PI;
    r.metrics[n + "_crossover"] = a.crossover;
    // One sentence a student can act on.
    std::string note = loop.what + ": ";
    if (!a.stable) {
      r.unstable = true;
      std::string poles;
      for (const auto& p : a.poles)
        if (p.real() >= 0 && p.imag() >= 0) poles += (poles.empty() ? "" : ", ") + fmtPole(p);
      note += "unstable, closed-loop pole" + std::string(poles.find(',') != std::string::npos ? "s" : "") + " at " + poles;
    } else {
      note += "stable (slowest pole " + fmtPole(a.poles.front()) + ", damping ζ = " + fmtNumber(a.min_damping) + ")";
    }
    note += "; delay margin " + fmtMs(a.delay_margin) + " against " + fmtMs(loop.delay) + " of delay";
    if (a.delay_margin < loop.delay) note += " — the delay alone destabilises it";
    r.notes.push_back(note + ".");
  }
  return r;
}

ScenarioRun runScenario(const Lab& lab, const Watchdog& wd, Deadline deadline, const std::string& config_file) {
  ScenarioRun out;
  out.screen = screenLoops(lab);
  Trace& tr = out.trace;
  tr.columns = lab.columns();
  const int t_col = tr.column("t");
  // Resolve the watchdog's columns once.
  std::vector<std::pair<int, const ColumnLimit*>> limits;
  for (const auto& l : wd.limits) {
    const int c = tr.column(l.column);
    if (c < 0) throw InputError(config_file, "/rubric/watchdog/limits", "expected a trace column of this lab, got \"" + l.column + "\"");
    limits.emplace_back(c, &l);
  }
  auto sim = lab.simulate(Engine::Hand);
  const long expected = std::lround(lab.duration() / lab.dt());
  tr.data.reserve(std::size_t(std::min(expected, wd.max_steps) + 1) * tr.columns.size());
  std::vector<double> row;
  auto stop = [&](double t, std::string why) {
    out.failure = std::move(why);
    out.failure_time = t;
  };
  for (long k = 0;; ++k) {
    if (k >= wd.max_steps) {
      stop(double(k) * lab.dt(), "stopped: the run exceeded its step budget of " + std::to_string(wd.max_steps) + " steps");
      break;
    }
    // The wall-time budget, checked every 1024 steps.
    if ((k & 1023) == 0 && std::chrono::steady_clock::now() > deadline) {
      out.out_of_time = true;
      stop(double(k) * lab.dt(), "not graded: the grading time budget ran out");
      break;
    }
    if (!sim->step(row)) break;
    tr.append(row);
    const double t = t_col >= 0 ? row[std::size_t(t_col)] : double(k) * lab.dt();
    // A non-finite value anywhere, or a watched column out of its range, ends the run.
    for (std::size_t c = 0; c < row.size() && out.failure.empty(); ++c)
      if (!std::isfinite(row[c])) stop(t, "unstable: " + tr.columns[c] + " became non-finite at t = " + fmtNumber(t) + " s");
    for (const auto& [c, lim] : limits) {
      if (!out.failure.empty()) break;
      const double x = row[std::size_t(c)];
      if (x < lim->min || x > lim->max)
        stop(t, "unstable: " + lim->what + " left its safe range [" + fmtNumber(lim->min) + ", " + fmtNumber(lim->max) +
                    "] at t = " + fmtNumber(t) + " s (" + lim->column + " = " + fmtNumber(x) + ")");
    }
    if (!out.failure.empty()) break;
  }
  if (out.failure.empty() && !sim->failure().empty()) {
    const double t = tr.rows() ? tr.at(tr.rows() - 1, t_col) : 0.0;
    stop(t, "unstable: " + sim->failure() + " at t = " + fmtNumber(t) + " s");
  }
  if (out.failure.empty()) out.metrics = lab.metrics(tr);
  for (const auto& [k, v] : out.screen.metrics.items()) out.metrics[k] = v;
  return out;
}

}  // namespace dyn
