// Screening and watched runs of one scenario; see scenario.h.
#include "grading/scenario.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "grading/grade.h"
#include "labs/numbers.h"
#include "physics/det/det.h"

namespace dyn {

std::string fmtNumber(double x) { return fmt("%.4g", x); }

namespace {

std::string fmtMs(double s) { return s >= kUnboundedDelay ? "unbounded" : fmtNumber(s * 1e3) + " ms"; }

std::string fmtPole(std::complex<double> p) {
  std::string s = (p.real() > 0 ? "+" : "") + fmtNumber(p.real());
  if (std::abs(p.imag()) > 1e-9) s += " ± " + fmtNumber(std::abs(p.imag())) + "j";
  return s + " rad/s";
}

// A loop with zero loop gain (an open-loop law, or zero gains) closes nothing.
bool hasFeedback(const LinearLoop& loop) {
  return std::any_of(loop.num.begin(), loop.num.end(), [](double c) { return c != 0; });
}

// Poles within this fraction of the largest pole's size of the imaginary axis do not decay: a pole
// at 0 (an integrator left without position feedback) is not stable.
constexpr double kMarginal = 1e-9;

// A loop's analysis depends only on these numbers, taken bit for bit (a −0 is not a 0).
std::string loopKey(const LinearLoop& loop) {
  std::string key;
  const auto add = [&](const void* p, std::size_t n) { key.append(static_cast<const char*>(p), n); };
  const auto poly = [&](const Poly& c) {
    const std::size_t n = c.size();
    add(&n, sizeof n);
    add(c.data(), n * sizeof(double));
  };
  const SampledLoop& z = loop.sampled;
  for (const Poly* c : {&loop.num, &loop.den, &z.plant_num, &z.plant_den, &z.ctrl_num, &z.ctrl_den}) poly(*c);
  for (double v : {loop.delay, z.period}) add(&v, sizeof v);
  for (int v : {loop.controller_integrators, z.steps}) add(&v, sizeof v);
  return key;
}

// analyseLoop, remembered for the last few loops: a grade's scenarios that leave a loop as it is (a
// noisy sensor, another start) screen the same loop, and the analysis (poles, a delay margin
// searched over frequency) is a pure function of its numbers, so a remembered one is the same bytes.
LoopAnalysis analysed(const LinearLoop& loop) {
  constexpr std::size_t kKept = 16;
  thread_local std::vector<std::pair<std::string, LoopAnalysis>> kept;  // oldest first
  std::string key = loopKey(loop);
  for (const auto& [k, a] : kept)
    if (k == key) return a;
  LoopAnalysis a = analyseLoop(loop);
  if (kept.size() == kKept) kept.erase(kept.begin());
  kept.emplace_back(std::move(key), a);
  return a;
}

}  // namespace

ScreenResult screenLoops(const Lab& lab) {
  ScreenResult r;
  for (const LinearLoop& loop : lab.linearise()) {
    const std::string& n = loop.name;
    if (!hasFeedback(loop)) {
      // Reported all the same, so every rubric metric exists: nothing to award.
      for (const char* m : {"_max_real_pole", "_damping", "_delay_margin", "_phase_margin_deg", "_crossover"})
        r.metrics[n + m] = 0.0;
      r.notes.push_back(loop.what + ": no feedback — no margin to award.");
      continue;
    }
    LoopAnalysis a = analysed(loop);
    double size = 0;
    for (const auto& p : a.poles) size = std::max(size, det::abs(p));
    const bool marginal = std::abs(a.max_real) <= kMarginal * size;  // the slowest pole on the axis
    if (marginal) a.stable = false;
    // A loop that is not stable has no damping to award (real poles in the right half plane
    // would otherwise read ζ = 1), and a marginal one no delay margin.
    if (!a.stable) a.min_damping = 0;
    if (marginal) a.delay_margin = 0;
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
      for (auto p : a.poles) {
        if (p.real() < -kMarginal * size || p.imag() < 0) continue;
        if (std::abs(p.real()) <= kMarginal * size) p.real(0.0);  // on the axis, up to rounding
        poles += (poles.empty() ? "" : ", ") + fmtPole(p);
      }
      note += marginal ? "not stable (a pole on the imaginary axis does not decay)" : "unstable";
      note += poles.find(',') != std::string::npos ? ", closed-loop poles at " : ", closed-loop pole at ";
      note += poles;
    } else {
      note += "stable (slowest pole " + fmtPole(a.poles.front()) + ", damping ζ = " + fmtNumber(a.min_damping) + ")";
    }
    note += "; delay margin " + fmtMs(a.delay_margin) + " against " + fmtMs(loop.delay) + " of delay";
    if (!marginal && a.delay_margin < loop.delay) note += " — the delay alone destabilises it";
    if (!loop.remark.empty()) note += "; " + loop.remark;
    r.notes.push_back(note + ".");
  }
  return r;
}

RowWatch::RowWatch(const Watchdog& wd, const std::vector<std::string>& columns, const std::string& config_file)
    : columns_(columns), max_steps_(wd.max_steps) {
  // Resolve the watchdog's columns once.
  for (const auto& l : wd.limits) {
    const auto it = std::find(columns.begin(), columns.end(), l.column);
    if (it == columns.end())
      throw InputError(config_file, "/rubric/watchdog/limits", "expected a trace column of this lab, got \"" + l.column + "\"");
    limits_.emplace_back(int(it - columns.begin()), l);
  }
}

std::string RowWatch::check(const std::vector<double>& row, double t) const {
  // A non-finite value anywhere, or a watched column out of its range, ends the run.
  for (std::size_t c = 0; c < row.size(); ++c)
    if (!std::isfinite(row[c])) return "unstable: " + columns_[c] + " became non-finite at t = " + fmtNumber(t) + " s";
  for (const auto& [c, lim] : limits_) {
    const double x = row[std::size_t(c)];
    if (x < lim.min || x > lim.max)
      return "unstable: " + lim.what + " left its safe range [" + fmtNumber(lim.min) + ", " + fmtNumber(lim.max) +
             "] at t = " + fmtNumber(t) + " s (" + lim.column + " = " + fmtNumber(x) + ")";
  }
  return {};
}

std::string RowWatch::budget(long steps) const {
  if (steps < max_steps_) return {};
  return "stopped: the run exceeded its step budget of " + std::to_string(max_steps_) + " steps";
}

json engineSummary(const Lab& lab, const WatchedRun& run) {
  const bool complete = run.failure.empty();
  json e = {{"status", complete ? "ok" : run.failure}, {"complete", complete}, {"trace_hash", run.trace.hash()}};
  if (complete) e["metrics"] = lab.metrics(run.trace);
  else e["stopped_at"] = run.failure_time;
  return e;
}

WatchedRun runWatched(const Lab& lab, Engine engine, const Watchdog& wd, Deadline deadline,
                      const std::string& config_file, const StopRequest& stop_request) {
  WatchedRun out;
  Trace& tr = out.trace;
  tr.columns = lab.columns();
  const int t_col = tr.column("t");
  const RowWatch watch(wd, tr.columns, config_file);
  auto sim = lab.simulate(engine);
  const long expected = std::lround(lab.duration() / lab.dt());
  tr.data.reserve(std::size_t(std::min(expected, wd.max_steps) + 1) * tr.columns.size());
  std::vector<double> row;
  auto stop = [&](double t, std::string why) {
    out.failure = std::move(why);
    out.failure_time = t;
  };
  for (long k = 0;; ++k) {
    if (std::string why = watch.budget(k); !why.empty()) {
      stop(double(k) * lab.dt(), std::move(why));
      break;
    }
    // The wall-time budget, checked every 1024 steps.
    if ((k & 1023) == 0 && std::chrono::steady_clock::now() > deadline) {
      out.out_of_time = true;
      stop(double(k) * lab.dt(), "not graded: the grading time budget ran out");
      break;
    }
    if ((k & 1023) == 0 && stop_request && stop_request()) {
      out.out_of_time = out.interrupted = true;
      stop(double(k) * lab.dt(), "not graded: the run was interrupted");
      break;
    }
    if (!sim->step(row)) break;
    tr.append(row);
    const double t = t_col >= 0 ? row[std::size_t(t_col)] : double(k) * lab.dt();
    if (std::string why = watch.check(row, t); !why.empty()) {
      stop(t, std::move(why));
      break;
    }
  }
  if (out.failure.empty() && !sim->failure().empty()) {
    const double t = tr.rows() ? tr.at(tr.rows() - 1, t_col) : 0.0;
    stop(t, stoppedSentence(sim->failure(), t));
  }
  return out;
}

json scenarioConfig(const json& applied, const Rubric& rubric, const Scenario& sc, const std::string& lab,
                    const std::string& config_file) {
  json cfg = mergePatch(applied, sc.patch);
  // The seed: fixed per lab and scenario, never the submission's, so the noise cannot be shopped for.
  const std::uint64_t seed = std::stoull(hashHex("noise/" + lab + "/" + sc.name), nullptr, 16) & ((1ull << 53) - 1);
  writeSeed(cfg, rubric, seed, config_file, sc.name);
  return cfg;
}

const Scenario& findScenario(const Rubric& rubric, const std::string& name, const std::string& option) {
  if (const Scenario* sc = rubric.scenario(name)) return *sc;
  std::string known;
  for (const Scenario& sc : rubric.scenarios) known += (known.empty() ? "" : ", ") + sc.name;
  throw InputError("<command line>", option,
                   "expected one of the rubric's scenarios (" + known + "), got \"" + name + "\"");
}

ScenarioRun runScenario(const Lab& lab, const Watchdog& wd, Deadline deadline, const std::string& config_file,
                        const StopRequest& stop) {
  ScenarioRun out;
  out.screen = screenLoops(lab);
  WatchedRun run = runWatched(lab, Engine::Hand, wd, deadline, config_file, stop);
  out.trace = std::move(run.trace);
  out.failure = std::move(run.failure);
  out.failure_time = run.failure_time;
  out.out_of_time = run.out_of_time;
  // A stopped run has no metrics of its own: only the screening's are scored.
  if (out.failure.empty()) out.metrics = lab.metrics(out.trace);
  for (const auto& [k, v] : out.screen.metrics.items()) out.metrics[k] = v;
  return out;
}

}  // namespace dyn
