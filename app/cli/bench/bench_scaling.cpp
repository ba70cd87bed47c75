// dynlab bench --scaling: the step cost of one open chain against its length, N = 3 … 1,000 links.
//   The chain: the motion-control arm's kind (planar revolute links in the vertical plane), every link
//   the arm's first one (a uniform 0.30 m, 1 kg rod), starting outstretched and falling under gravity
//   with τ = 0. Links keep their size as N grows: with the total length fixed instead, the chain's
//   fastest mode grows ∝ N √(g/L) and a 1 ms first-order step goes unstable long before N = 1,000,
//   so the larger chains would be timed on a blown-up state.
//   Three engines, all first order with one dynamics evaluation per step (semi-implicit Euler,
//   θ' += dt θ'', then θ += dt θ', Bullet's own order), dt = 1 ms:
//     hand ABA               positionKinematics, velocityKinematics, aba: O(N)
//     hand CRBA + Cholesky   rnea (θ'' = 0), crba, Eigen LLT: O(N²) to form M, O(N³) to factor it
//     Bullet btMultiBody     physics/bullet/bullet_chain.h (Featherstone's ABA inside Bullet)
//   Mean µs per step (outliers left out) over at least kMinSteps steps and kBudget seconds each (fewer steps for the
//   slowest: the CRBA at N = 1,000 takes tenths of a second a step).
//   Agreement: the tip after 0.5 s, hand ABA against Bullet and against the CRBA route, from the same
//   state with the same scheme: what is left is rounding (and, later in a run, its growth: a falling
//   chain is chaotic, so after a few seconds no two engines agree on where the tip is).
// Writes OUT/scaling.csv and OUT/scaling.png (log–log, PLplot); prints a table (or JSON with --json).
#include <plplot/plplot.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "app/cli/bench/bench.h"
#include "app/cli/commands.h"
#include "app/shared/progress.h"
#include "labs/file_write.h"
#include "physics/bullet/bullet_chain.h"
#include "physics/chain.h"
#include "physics/det/det.h"
#include "render/image.h"

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace dyn::app {
namespace {

constexpr int kSizes[] = {3, 10, 30, 100, 300, 1000};
constexpr double kLength = 0.30, kMass = 1.0, kDt = 1e-3;  // the motion-control arm's first link
constexpr double kBudget = 0.25;                          // s of stepping timed per engine and size
constexpr int kMinSteps = 5, kMaxSteps = 3000;
constexpr double kAgreeTime = 0.5;                         // s: when the tips are compared

// One engine on one chain, stepped with τ = 0.
class Stepper {
 public:
  virtual ~Stepper() = default;
  virtual void step() = 0;
  virtual Eigen::Vector2d tip() const = 0;
};

class HandStepper : public Stepper {
 public:
  HandStepper(const TreeModel<Planar>& tree, bool crba_route)
      : tree_(tree), data_(tree_), crba_(crba_route), n_(tree.dof()), q_(Eigen::VectorXd::Zero(n_)),
        qd_(Eigen::VectorXd::Zero(n_)), qdd_(n_), tau_(Eigen::VectorXd::Zero(n_)), zero_(Eigen::VectorXd::Zero(n_)),
        h_(n_), M_(crba_route ? n_ : 0, crba_route ? n_ : 0), llt_(crba_route ? n_ : 0) {}
  void step() override {
    positionKinematics(tree_, q_, data_);
    velocityKinematics(tree_, qd_, data_);
    if (crba_) {  // M θ'' = τ − (Cθ' + G)
      rnea(tree_, data_, qd_, zero_, h_);
      crba(tree_, data_, M_);
      llt_.compute(M_);
      qdd_ = tau_ - h_;
      llt_.solveInPlace(qdd_);
    } else {
      aba(tree_, data_, qd_, tau_, qdd_);
    }
    qd_ += kDt * qdd_;
    q_ += kDt * qd_;
  }
  Eigen::Vector2d tip() const override {
    TreeData<Planar> d(tree_);
    positionKinematics(tree_, q_, d);
    return pointPosition(d, n_ - 1, Planar::Pos(kLength, 0.0));
  }

 private:
  TreeModel<Planar> tree_;
  TreeData<Planar> data_;
  bool crba_;
  int n_;
  Eigen::VectorXd q_, qd_, qdd_, tau_, zero_, h_;
  Eigen::MatrixXd M_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
};

class BulletStepper : public Stepper {
 public:
  explicit BulletStepper(const TreeModel<Planar>& tree)
      : chain_(tree, kDt, Eigen::VectorXd::Zero(tree.dof()), Eigen::VectorXd::Zero(tree.dof())),
        tau_(Eigen::VectorXd::Zero(tree.dof())) {}
  void step() override { chain_.step(tau_); }
  Eigen::Vector2d tip() const override { return chain_.pointPosition(chain_.dof() - 1, {kLength, 0.0}); }

 private:
  bullet::BulletChain chain_;
  Eigen::VectorXd tau_;
};

enum Engine { kAba, kCrba, kBullet, kEngines };
const char* const kEngineNames[kEngines] = {"hand ABA", "hand CRBA + Cholesky", "Bullet btMultiBody"};

std::unique_ptr<Stepper> makeStepper(Engine e, const TreeModel<Planar>& tree) {
  if (e == kBullet) return std::make_unique<BulletStepper>(tree);
  return std::make_unique<HandStepper>(tree, e == kCrba);
}

// µs per step from the outstretched start, each step timed alone (less the clock's own cost): their
// mean without outliers (timing.h meanWithoutOutliers: a median would stick to the clock's ~10 ns ticks).
double stepMicros(Engine e, const TreeModel<Planar>& tree, double clock_us, int& steps) {
  using Micros = std::chrono::duration<double, std::micro>;
  auto s = makeStepper(e, tree);
  std::vector<double> t;
  const auto start = Clock::now();
  while (int(t.size()) < kMaxSteps &&
         (int(t.size()) < kMinSteps || std::chrono::duration<double>(Clock::now() - start).count() < kBudget)) {
    const auto t0 = Clock::now();
    s->step();
    t.push_back(Micros(Clock::now() - t0).count() - clock_us);
  }
  steps = int(t.size());
  return meanWithoutOutliers(t);
}

// The tip after kAgreeTime s.
Eigen::Vector2d tipAfter(Engine e, const TreeModel<Planar>& tree) {
  auto s = makeStepper(e, tree);
  for (int k = 0; k < int(std::lround(kAgreeTime / kDt)); ++k) s->step();
  return s->tip();
}

struct Row {
  int n = 0;
  double us[kEngines] = {0, 0, 0};
  int steps[kEngines] = {0, 0, 0};
  double tip_bullet = 0, tip_crba = 0;  // m: |tip(ABA) − tip(other)| after kAgreeTime
};

// ---------------------------------------------------------------- the figure
enum : PLINT { kPaper = 0, kInk = 1, kGrid = 2, kAxis = 3, kLine0 = 4 };
int plplotFailed(const char* message) { throw std::runtime_error(std::string("PLplot: ") + message); }

// log–log: µs per step against N, one line with markers per engine, a dotted ∝ N and ∝ N³ guide.
Image drawFigure(const std::vector<Row>& rows, int width, int height) {
  Image image{width, height, std::vector<std::uint8_t>(std::size_t(width) * height * 4, 255)};
  std::vector<unsigned char> pixels(image.rgba.size(), 255);
  double ylo = INFINITY, yhi = -INFINITY;
  for (const Row& r : rows)
    for (double u : r.us) ylo = std::min(ylo, det::log10(u)), yhi = std::max(yhi, det::log10(u));
  ylo = std::floor(ylo - 0.1), yhi = std::ceil(yhi + 0.1);
  const double xlo = det::log10(2.0), xhi = det::log10(1500.0);
  PLINT previous, mine;
  plgstrm(&previous);
  plmkstrm(&mine);
  try {
    plsexit(plplotFailed);
    plsdev("memcairo");
    plsmema(width, height, pixels.data());
    plspage(72, 72, width, height, 0, 0);
    plsfam(0, 0, 0);
    plscol0(kPaper, 255, 255, 255);
    plscol0(kInk, 0, 0, 0);
    plscol0(kGrid, 225, 225, 225);
    plscol0(kAxis, 60, 60, 60);
    const int palette[kEngines][3] = {{0, 114, 178}, {213, 94, 0}, {0, 158, 115}};  // colour-blind safe
    for (int e = 0; e < kEngines; ++e) plscol0(kLine0 + e, palette[e][0], palette[e][1], palette[e][2]);
    plinit();
    pladv(0);
    plschr(0, 1.0);
    plvpor(0.10, 0.70, 0.12, 0.90);
    plwind(xlo, xhi, ylo, yhi);
    plcol0(kGrid);
    plbox("glh", 0, 0, "glh", 0, 0);  // a grid at every decade and its 2, 3 … 9
    plcol0(kAxis);
    plbox("bcnlst", 0, 0, "bcnlstv", 0, 0);
    plcol0(kInk);
    pllab("links N", "µs per step (mean)", "");
    plmtex("t", 1.5, 0.5, 0.5, "Step cost of an open planar chain, dt = 1 ms, first order");
    // Guides through the ABA line's first point (∝ N) and the CRBA line's last point (∝ N³).
    const double gx[2] = {xlo, xhi};
    const double a0 = det::log10(rows.front().us[kAba]) - det::log10(double(rows.front().n));
    const double c0 = det::log10(rows.back().us[kCrba]) - 3 * det::log10(double(rows.back().n));
    const double ga[2] = {a0 + gx[0], a0 + gx[1]}, gc[2] = {c0 + 3 * gx[0], c0 + 3 * gx[1]};
    plcol0(kAxis);
    pllsty(3);
    plwidth(1.0);
    plline(2, gx, ga);
    plline(2, gx, gc);
    pllsty(1);
    std::vector<double> x, y;
    for (int e = 0; e < kEngines; ++e) {
      x.clear(), y.clear();
      for (const Row& r : rows) x.push_back(det::log10(double(r.n))), y.push_back(det::log10(r.us[e]));
      plcol0(kLine0 + e);
      plwidth(2.5);
      plline(PLINT(x.size()), x.data(), y.data());
      plpoin(PLINT(x.size()), x.data(), y.data(), 17);
    }
    // Legend in the right-hand column.
    plvpor(0.71, 0.99, 0.12, 0.90);
    plwind(0, 1, 0, 1);
    const char* texts[kEngines + 1] = {kEngineNames[kAba], kEngineNames[kCrba], kEngineNames[kBullet], "∝ N and ∝ N³"};
    PLINT opts[kEngines + 1], colours[kEngines + 1], styles[kEngines + 1], text_colours[kEngines + 1];
    PLFLT widths[kEngines + 1];
    for (int k = 0; k <= kEngines; ++k)
      opts[k] = PL_LEGEND_LINE, colours[k] = k < kEngines ? kLine0 + k : kAxis, styles[k] = k < kEngines ? 1 : 3,
      widths[k] = k < kEngines ? 2.5 : 1.0, text_colours[k] = kInk;
    PLFLT lw, lh;
    pllegend(&lw, &lh, PL_LEGEND_BACKGROUND, PL_POSITION_TOP | PL_POSITION_LEFT | PL_POSITION_INSIDE, 0.02, 0.0, 0.15,
             kPaper, kAxis, 1, 0, 0, kEngines + 1, opts, 0.6, 0.8, 1.6, 0.0, text_colours, texts, nullptr, nullptr,
             nullptr, nullptr, colours, styles, widths, nullptr, nullptr, nullptr, nullptr);
    plend1();
    plsstrm(previous);
  } catch (...) {
    plend1();
    plsstrm(previous);
    throw;
  }
  // memcairo draws into RGB(A) bytes in the order cairo's image surface keeps them: 4 bytes a pixel.
  for (std::size_t k = 0; k < image.rgba.size(); k += 4)
    image.rgba[k] = pixels[k], image.rgba[k + 1] = pixels[k + 1], image.rgba[k + 2] = pixels[k + 2], image.rgba[k + 3] = 255;
  return image;
}

std::string csvOf(const std::vector<Row>& rows) {
  std::ostringstream s;
  s.precision(6);
  s << "links,aba_us,crba_cholesky_us,bullet_us,aba_us_per_link,crba_cholesky_us_per_link,bullet_us_per_link,"
       "bullet_over_aba,crba_over_aba,aba_steps,crba_steps,bullet_steps,tip_aba_vs_bullet_m,tip_aba_vs_crba_m\n";
  for (const Row& r : rows) {
    s << r.n;
    for (double u : r.us) s << ',' << u;
    for (double u : r.us) s << ',' << u / r.n;
    s << ',' << r.us[kBullet] / r.us[kAba] << ',' << r.us[kCrba] / r.us[kAba];
    for (int k : r.steps) s << ',' << k;
    s << ',' << r.tip_bullet << ',' << r.tip_crba << '\n';
  }
  return s.str();
}

}  // namespace

int benchScaling(const BenchArgs& a) {
  if (!a.lab.empty()) {
    std::fprintf(stderr, "error: <command line>: --scaling times a chain, not a lab: leave LAB out\n");
    return 2;
  }
  // The output folder first: a bad --out fails before half a minute of timing, not after.
  const fs::path out = a.out.empty() ? fs::path("out/bench") : fs::path(a.out);
  try {
    fs::create_directories(out);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: --out: %s\n", e.what());
    return 2;
  }
  const double clock_us = clockOverhead();
  std::vector<Row> rows;
  Progress progress("chains", std::size(kSizes) * (kEngines + 1));
  for (int n : kSizes) {
    const TreeModel<Planar> tree = uniformPlanarChain(n, kLength, kMass);
    Row r;
    r.n = n;
    for (int e = 0; e < kEngines; ++e) {
      r.us[e] = stepMicros(Engine(e), tree, clock_us, r.steps[e]);
      progress.set(rows.size() * (kEngines + 1) + std::size_t(e) + 1);
    }
    const Eigen::Vector2d tip = tipAfter(kAba, tree);
    r.tip_bullet = (tip - tipAfter(kBullet, tree)).norm();
    r.tip_crba = (tip - tipAfter(kCrba, tree)).norm();
    rows.push_back(r);
    progress.set(rows.size() * (kEngines + 1));
  }
  progress.done();
  try {
    writeFileChecked((out / "scaling.csv").string(), csvOf(rows));
    std::string why;
    if (!writePng((out / "scaling.png").string(), drawFigure(rows, 900, 540), &why))
      throw std::runtime_error("cannot write " + (out / "scaling.png").string() + ": " + why);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  if (a.json) {
    json j = json::array();
    for (const Row& r : rows)
      j.push_back({{"links", r.n},
                   {"aba_us", r.us[kAba]},
                   {"crba_cholesky_us", r.us[kCrba]},
                   {"bullet_us", r.us[kBullet]},
                   {"bullet_over_aba", r.us[kBullet] / r.us[kAba]},
                   {"crba_over_aba", r.us[kCrba] / r.us[kAba]},
                   {"tip_aba_vs_bullet_m", r.tip_bullet},
                   {"tip_aba_vs_crba_m", r.tip_crba}});
    std::cout << json{{"scaling", j}, {"dt", kDt}, {"link_length", kLength}, {"link_mass", kMass}}.dump() << "\n";
    return 0;
  }
  std::printf("Step cost of an open planar chain: 0.30 m, 1 kg uniform links, falling from outstretched with τ = 0;\n"
              "dt = 1 ms, semi-implicit Euler in all three; mean µs per step. tip: |Δ tip position| after %.1f s\n"
              "between the hand ABA run and the Bullet (or CRBA) run from the same start.\n\n",
              kAgreeTime);
  std::printf("%6s  %18s  %26s  %18s  %10s  %10s  %12s  %12s\n", "links", "hand ABA", "hand CRBA + Cholesky",
              "Bullet", "Bullet/ABA", "CRBA/ABA", "tip: Bullet", "tip: CRBA");
  std::printf("%6s  %18s  %26s  %18s  %10s  %10s  %12s  %12s\n", "", "µs (µs/link)", "µs (µs/link)", "µs (µs/link)",
              "", "", "m", "m");
  for (const Row& r : rows) {
    char cell[kEngines][40];
    for (int e = 0; e < kEngines; ++e) std::snprintf(cell[e], sizeof cell[e], "%.3g (%.3g)", r.us[e], r.us[e] / r.n);
    std::printf("%6d  %18s  %26s  %18s  %9.1fx  %9.1fx  %12.1e  %12.1e\n", r.n, cell[kAba], cell[kCrba], cell[kBullet],
                r.us[kBullet] / r.us[kAba], r.us[kCrba] / r.us[kAba], r.tip_bullet, r.tip_crba);
  }
  std::printf("\nwrote %s and %s\n", (out / "scaling.csv").string().c_str(), (out / "scaling.png").string().c_str());
  return 0;
}

}  // namespace dyn::app
