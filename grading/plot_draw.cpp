// Drawing a plot on a PLplot stream; see plot_draw.h.
// Sized in pixels at 72 dpi, white background, light grid, Okabe–Ito colours. Layers, bottom to
// top: hatched spans, faint (noisy) series, bands, solid series, dashed series, markers, frame; the
// legend right of the frame when it is narrow, else below it: never over the data.
// Every number PLplot sees is finite (the data are split into finite runs). An x–y plot has no
// spans or markers (x is not time); equal aspect widens one range to the frame's shape, then trims
// the frame so a unit is as long along x as along y.
#include "grading/plot_draw.h"

#include <plplot/plplot.h>

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "physics/det/det.h"

namespace dyn::plot_detail {
namespace {

constexpr double kMmPerPx = 25.4 / 72.0;  // the cairo devices' resolution: 1 px = 1 pt
constexpr double kHuge = 1e100;           // |values| beyond this are clamped (PLplot needs finite spans)
constexpr double kCharHeightPx = 9.0;     // PLplot character height: ~12 px tick labels, 15 px title
constexpr double kGlyphWidth = 0.7;       // a generous average glyph width, in character heights
constexpr double kTitleGlyphWidth = 0.85; // the bold title's (measured ~0.78 on long titles)
constexpr double kMaxRightLegend = 0.3;   // wider legends (fraction of the page) go below the frame
constexpr double kXTicks = 8, kYTicks = 6;  // about this many tick intervals per axis
constexpr double kRough = 40;             // a series crossing its range this often is noise-like
constexpr double kLogDecades = 3;         // Auto: log y when the positive data span more decades

// cmap0 slots: fixed colours first, then the series palette, then its faint (translucent) twin.
enum Col : PLINT { kWhite = 0, kInk = 1, kGrid = 2, kBand = 3, kMarker = 4, kAxis = 5, kLegendEdge = 6, kSpan = 7, kPalette0 = 8 };
struct Rgb { int r, g, b; };
// Okabe & Ito's colour-blind-safe palette, ordered for contrast on white (yellow left out).
constexpr Rgb kPalette[] = {{0, 114, 178}, {213, 94, 0},   {0, 158, 115}, {204, 121, 167},
                            {230, 159, 0}, {86, 180, 233}, {0, 0, 0}};
constexpr int kPaletteSize = sizeof kPalette / sizeof kPalette[0];
constexpr PLINT kFaint0 = kPalette0 + kPaletteSize;

// Characters (code points) of UTF-8 text, and its first n of them.
std::size_t utf8Chars(const std::string& s) {
  return static_cast<std::size_t>(std::count_if(s.begin(), s.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}
std::string utf8Prefix(const std::string& s, std::size_t n) {
  std::size_t at = 0;
  for (std::size_t seen = 0; at < s.size(); ++at)
    if ((static_cast<unsigned char>(s[at]) & 0xC0) != 0x80 && seen++ == n) break;
  return s.substr(0, at);
}

// PLplot reads '#' as its escape character; "##" is a literal '#'.
std::string plText(const std::string& s) {
  std::string out;
  for (char c : s) out += (c == '#') ? std::string("##") : std::string(1, c);
  return out;
}

double clampHuge(double v) { return std::clamp(v, -kHuge, kHuge); }

// [begin, end) index runs where ok(i) holds.
template <class Ok>
std::vector<std::pair<size_t, size_t>> runs(size_t n, Ok ok) {
  std::vector<std::pair<size_t, size_t>> out;
  for (size_t i = 0; i < n;) {
    while (i < n && !ok(i)) ++i;
    const size_t b = i;
    while (i < n && ok(i)) ++i;
    if (b < i) out.push_back({b, i});
  }
  return out;
}

bool finitePoint(const PlotSeries& s, size_t i) { return std::isfinite(s.x[i]) && std::isfinite(s.y[i]); }

// Thins a run to at most `budget` points: each bucket keeps its min and max, in time order.
void appendThinned(const std::vector<double>& x, const std::vector<double>& y, size_t b, size_t e,
                   size_t budget, std::vector<double>& ox, std::vector<double>& oy) {
  const size_t n = e - b;
  if (n <= budget || budget < 4) {
    for (size_t i = b; i < e; ++i) ox.push_back(x[i]), oy.push_back(y[i]);
    return;
  }
  const size_t buckets = budget / 2;
  for (size_t k = 0; k < buckets; ++k) {
    const size_t lo = b + n * k / buckets, hi = b + n * (k + 1) / buckets;
    size_t imin = lo, imax = lo;
    for (size_t i = lo; i < hi; ++i) {
      if (y[i] < y[imin]) imin = i;
      if (y[i] > y[imax]) imax = i;
    }
    const size_t first = std::min(imin, imax), second = std::max(imin, imax);
    ox.push_back(x[first]), oy.push_back(y[first]);
    if (second != first) ox.push_back(x[second]), oy.push_back(y[second]);
  }
}

// A "nice" tick step (1, 2 or 5 × 10^k) giving about `target` intervals over the span (the
// thresholds are the geometric midpoints between 1, 2, 5 and 10).
double niceStep(double span, double target) {
  const double raw = span / target, mag = det::pow(10.0, std::floor(det::log10(raw))), r = raw / mag;
  return (r < 1.414 ? 1.0 : r < 3.162 ? 2.0 : r < 7.071 ? 5.0 : 10.0) * mag;
}

// Tick labels with just enough decimals for the step; "%g" for very large or small numbers; on a
// log axis the value is the exponent and the label 10 to its power.
struct TickFormat {
  double step = 1, max_abs = 1;
  bool log = false;
  std::string format(double v) const {
    char buf[64];
    if (std::abs(v) < 1e-9 * step) v = 0.0;  // no "-0.00"
    if (log) {
      std::snprintf(buf, sizeof buf, "10#u%d#d", static_cast<int>(std::lround(v)));
    } else if (max_abs >= 1e6 || step < 1e-4) {
      std::snprintf(buf, sizeof buf, "%.3g", v);
    } else {
      const int decimals = std::max(0, -static_cast<int>(std::floor(det::log10(step) + 1e-9)));
      std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    }
    return buf;
  }
  // Width in glyphs (the escapes of a log label draw nothing; its exponent is small).
  size_t glyphs(double v) const { return log ? format(v).size() - 4 : format(v).size(); }
};
TickFormat tick_x, tick_y;  // read by the label callback (under plot.cpp's mutex)

void tickLabel(PLINT axis, PLFLT value, char* label, PLINT length, PLPointer) {
  const std::string s = (axis == PL_X_AXIS ? tick_x : tick_y).format(value);
  std::snprintf(label, static_cast<size_t>(length), "%s", s.c_str());
}

// Longest tick label on an axis (for the margin that has to hold it).
size_t widestTick(const TickFormat& f, double lo, double hi) {
  size_t w = 1;
  const double first = std::ceil(lo / f.step) * f.step;
  for (int k = 0; k < 100 && first + k * f.step <= hi + 1e-9 * f.step; ++k) w = std::max(w, f.glyphs(first + k * f.step));
  return w;
}

// UTF-8 characters in s (for width estimates).
size_t glyphs(const std::string& s) {
  return static_cast<size_t>(std::count_if(s.begin(), s.end(), [](unsigned char c) { return (c & 0xC0) != 0x80; }));
}

PLINT seriesColour(int color, bool faint) {
  return (faint ? kFaint0 : kPalette0) + ((color % kPaletteSize) + kPaletteSize) % kPaletteSize;
}
// PLplot's patterns: 1 solid, 3 long dashes, 2 short dashes, 5 long and short dashes.
PLINT seriesStyle(PlotSeries::Style s) {
  switch (s) {
    case PlotSeries::Style::Dashed: return 3;
    case PlotSeries::Style::Dotted: return 2;
    case PlotSeries::Style::DashDot: return 5;
    default: return 1;
  }
}

// How often a series crosses its own range: Σ|Δy| / (max − min). A smooth response over a few
// periods scores under 10; sensor noise sampled every step, hundreds.
double roughness(const PlotSeries& s) {
  Range r;
  double travel = 0;
  for (auto [b, e] : runs(s.x.size(), [&](size_t i) { return finitePoint(s, i); }))
    for (size_t i = b; i < e; ++i) {
      r.add(s.y[i]);
      if (i > b) travel += std::abs(clampHuge(s.y[i]) - clampHuge(s.y[i - 1]));
    }
  return r.empty() || r.hi <= r.lo ? 0.0 : travel / (r.hi - r.lo);
}

// Log y for Auto: nothing negative, and the bulk of the positive values (5th to 95th percentile)
// spans more than kLogDecades decades (a 1e-14 residual beside a 1e-7 one).
bool wantsLog(const PlotSpec& spec) {
  std::vector<double> pos;
  for (const auto& s : spec.series)
    for (size_t i = 0; i < s.y.size(); ++i) {
      if (!finitePoint(s, i)) continue;
      if (s.y[i] < 0) return false;
      if (s.y[i] > 0) pos.push_back(s.y[i]);
    }
  if (pos.size() < 2) return false;
  const size_t lo = pos.size() / 20, hi = pos.size() - 1 - pos.size() / 20;
  std::nth_element(pos.begin(), pos.begin() + lo, pos.end());
  const double p5 = pos[lo];
  std::nth_element(pos.begin(), pos.begin() + hi, pos.end());
  return det::log10(pos[hi] / p5) > kLogDecades;
}

// y → log10 y (values ≤ 0 become gaps; a band's lower edge at or below 0 goes to the smallest
// positive value in the plot).
void toLog(PlotSpec& spec) {
  double smallest = INFINITY;
  for (const auto& s : spec.series)
    for (double v : s.y)
      if (std::isfinite(v) && v > 0) smallest = std::min(smallest, v);
  const auto lg = [](double v) { return std::isfinite(v) && v > 0 ? det::log10(v) : NAN; };
  for (auto& s : spec.series)
    for (double& v : s.y) v = lg(v);
  for (auto& b : spec.bands)
    for (size_t i = 0; i < b.x.size(); ++i) {
      if (!(b.lo[i] > 0) && std::isfinite(smallest)) b.lo[i] = smallest;
      b.lo[i] = lg(b.lo[i]), b.hi[i] = lg(b.hi[i]);
    }
}

// Axis ranges from the finite data and the markers; x is tight, y gets 5% headroom (log y: whole
// decades). A run that is NaN from the start still gets its time axis (and y in [-1, 1]).
void setRanges(const std::string& path, Prepared& p) {
  const PlotSpec& spec = p.spec;
  Range xr, yr;
  for (const auto& s : spec.series)
    for (size_t i = 0; i < s.x.size(); ++i)
      if (std::isfinite(s.x[i])) xr.add(s.x[i]), yr.add(s.y[i]);
  for (const auto& b : spec.bands)
    for (size_t i = 0; i < b.x.size(); ++i)
      if (std::isfinite(b.x[i])) xr.add(b.x[i]), yr.add(b.lo[i]), yr.add(b.hi[i]);
  if (!spec.parametric)
    for (double v : spec.vlines) xr.add(v);
  if (xr.empty()) throw std::runtime_error("writePlot " + path + ": no finite x values to plot");
  if (yr.empty()) yr = {0.0, 0.0};
  xr.widenIfFlat();
  // A parametric plot's x is data: 5% headroom each side like y, and it is drawn as it is.
  if (spec.parametric) {
    yr.widenIfFlat();
    const double px = 0.05 * (xr.hi - xr.lo), py = 0.05 * (yr.hi - yr.lo);
    p.xr = {xr.lo - px, xr.hi + px};
    p.yr = {yr.lo - py, yr.hi + py};
    return;
  }
  // A marker on the last sample (a run that stopped) would hide in the frame: leave it some room.
  for (double v : spec.vlines)
    if (std::isfinite(v) && xr.hi - v < 0.01 * (xr.hi - xr.lo)) xr.hi = v + 0.03 * (xr.hi - xr.lo);
  // An x range ending just short of a tick (t = 0 … 3.999 s) is stretched to it (4.0 s is labelled).
  const double span = xr.hi - xr.lo, step = niceStep(span, kXTicks);
  const double lo = std::floor(xr.lo / step + 1e-9) * step, hi = std::ceil(xr.hi / step - 1e-9) * step;
  if (xr.lo - lo < 0.02 * span) xr.lo = lo;
  if (hi - xr.hi < 0.02 * span) xr.hi = hi;
  if (p.log_y) {
    yr = {std::floor(yr.lo + 1e-9), std::ceil(yr.hi - 1e-9)};
    if (yr.hi <= yr.lo) yr.hi = yr.lo + 1;
  } else {
    yr.widenIfFlat();
    const double pad = 0.05 * (yr.hi - yr.lo);
    yr = {yr.lo - pad, yr.hi + pad};
  }
  p.xr = xr;
  p.yr = yr;
}

void drawSpan(const PlotSpan& s, const Range& xr, const Range& yr, double scale) {
  const double x0 = std::max(std::min(s.x0, s.x1), xr.lo), x1 = std::min(std::max(s.x0, s.x1), xr.hi);
  if (!(x1 > x0)) return;
  PLFLT px[4] = {x0, x1, x1, x0}, py[4] = {yr.lo, yr.lo, yr.hi, yr.hi};
  plcol0(kSpan);
  plwidth(scale);
  plpsty(3);  // 45° hatching
  plfill(4, px, py);
  plpsty(0);
}

void drawBand(const PlotBand& b, size_t budget) {
  plcol0(kBand);
  const auto ok = [&](size_t i) { return std::isfinite(b.x[i]) && std::isfinite(b.lo[i]) && std::isfinite(b.hi[i]); };
  for (auto [s, e] : runs(b.x.size(), ok)) {
    // Polygon: along hi forwards, back along lo; each edge thinned as a series is (a polygon of
    // 8,000 corners cost cairo more than the rest of the plot).
    std::vector<PLFLT> px, py, lx, ly;
    const size_t keep = std::max<size_t>(4, budget * (e - s) / b.x.size());
    appendThinned(b.x, b.hi, s, e, keep, px, py);
    appendThinned(b.x, b.lo, s, e, keep, lx, ly);
    if (px.back() != b.x[e - 1]) px.push_back(b.x[e - 1]), py.push_back(b.hi[e - 1]), lx.push_back(b.x[e - 1]), ly.push_back(b.lo[e - 1]);
    px.insert(px.end(), lx.rbegin(), lx.rend());
    py.insert(py.end(), ly.rbegin(), ly.rend());
    for (auto& v : px) v = clampHuge(v);
    for (auto& v : py) v = clampHuge(v);
    if (e - s == 1) {  // a single sample: a hairline
      pllsty(1);
      plline(2, px.data(), py.data());
    } else {
      plfill(static_cast<PLINT>(px.size()), px.data(), py.data());
    }
  }
}

// A noise-like series as pieces of 16 segments sharing end points: cairo keeps each edge of a path
// active over the rows it spans, and one zigzag across the frame cost two thirds of its plot.
void strokeInPieces(const std::vector<PLFLT>& px, const std::vector<PLFLT>& py) {
  for (size_t k = 0; k + 1 < px.size(); k += 16) plline(PLINT(std::min<size_t>(17, px.size() - k)), px.data() + k, py.data() + k);
}

void drawSeries(const PlotSeries& s, bool faint, size_t budget, double scale) {
  plcol0(seriesColour(s.color, faint));
  pllsty(seriesStyle(s.style));
  plwidth((faint ? 0.8 : 2.0) * scale);
  for (auto [b, e] : runs(s.x.size(), [&](size_t i) { return finitePoint(s, i); })) {
    std::vector<PLFLT> px, py;
    appendThinned(s.x, s.y, b, e, std::max<size_t>(4, budget * (e - b) / s.x.size()), px, py);
    for (size_t i = 0; i < px.size(); ++i) px[i] = clampHuge(px[i]), py[i] = clampHuge(py[i]);
    if (px.size() == 1) {
      plpoin(1, px.data(), py.data(), 17);  // an isolated finite sample: a dot
    } else if (faint && s.style == PlotSeries::Style::Solid) {  // a dash pattern would restart per piece
      strokeInPieces(px, py);
    } else {
      plline(static_cast<PLINT>(px.size()), px.data(), py.data());
    }
  }
  pllsty(1);
}

// The first n UTF-8 characters of s, with "…" when it had more.
std::string clip(const std::string& s, size_t n) {
  if (glyphs(s) <= n) return s;
  size_t kept = 0, i = 0;
  for (; i < s.size(); ++i)
    if ((static_cast<unsigned char>(s[i]) & 0xC0) != 0x80 && kept++ == n - 1) break;
  return s.substr(0, i) + "\u2026";
}

// The legend: spans (hatched boxes), bands (filled boxes), series (line samples), then the
// markers, in spec order. Sizes are estimates in mm for character height ch (PLplot only measures
// while it draws); texts too long for the page are clipped with "…".
struct Legend {
  std::vector<std::string> texts;
  std::vector<PLINT> opts, text_colors, box_colors, box_patterns, line_colors, line_styles;
  std::vector<PLFLT> box_scales, box_widths, line_widths;
  double scale, ch;

  Legend(const Prepared& p, double scale, double ch, double page_w) : scale(scale), ch(ch) {
    for (const auto& s : p.spec.spans)
      if (!s.label.empty() && !p.spec.parametric) add(s.label, PL_LEGEND_COLOR_BOX, kSpan, 3, kInk, 1, scale);
    for (const auto& b : p.spec.bands)
      if (!b.label.empty()) add(b.label, PL_LEGEND_COLOR_BOX, kBand, 0, kInk, 1, scale);
    for (size_t i = 0; i < p.spec.series.size(); ++i) {
      const PlotSeries& s = p.spec.series[i];
      if (!s.label.empty())
        add(s.label, PL_LEGEND_LINE, kInk, 0, seriesColour(s.color, p.faint[i]), seriesStyle(s.style),
            (p.faint[i] ? 1.2 : 2.0) * scale);
    }
    if (!p.spec.parametric && !p.spec.vlines.empty() && !p.spec.vline_label.empty())
      add(p.spec.vline_label, PL_LEGEND_LINE, kInk, 0, kMarker, 2, 2.0 * scale);
    const double room = page_w - 2 * ch - (entryMm() - chars() * kGlyphWidth * ch);
    const size_t most = static_cast<size_t>(std::max(4.0, room / (kGlyphWidth * ch)));
    for (auto& t : texts) t = clip(t, most);
  }
  void add(const std::string& text, PLINT opt, PLINT box, PLINT pattern, PLINT line, PLINT style, double width) {
    texts.push_back(text);
    opts.push_back(opt);
    text_colors.push_back(kInk);
    box_colors.push_back(box);
    box_patterns.push_back(pattern);
    box_scales.push_back(0.9);
    box_widths.push_back(scale);
    line_colors.push_back(line);
    line_styles.push_back(style);
    line_widths.push_back(width);
  }
  bool empty() const { return texts.empty(); }
  size_t chars() const {
    size_t n = 0;
    for (const auto& t : texts) n = std::max(n, glyphs(t));
    return n;
  }
  double sampleMm() const { return 4.5 * ch; }
  double entryMm() const { return sampleMm() + 2.5 * ch + chars() * kGlyphWidth * ch + 1.5 * ch; }
  double heightMm(int rows) const { return (2.0 * rows + 0.6) * ch; }

  // Draws with its top-left corner at (x, y) right of/below the viewport's top-left corner, in
  // fractions of the viewport; returns its size in the same fractions.
  std::pair<double, double> draw(double x, double y, int rows, int columns, double viewport_w_mm) const {
    std::vector<std::string> escaped;
    for (const auto& t : texts) escaped.push_back(plText(t));
    std::vector<const char*> ctext;
    for (const auto& t : escaped) ctext.push_back(t.c_str());
    PLFLT w = 0, h = 0;
    pllegend(&w, &h, PL_LEGEND_BACKGROUND | (columns > 1 ? PL_LEGEND_ROW_MAJOR : 0),
             PL_POSITION_LEFT | PL_POSITION_TOP | PL_POSITION_INSIDE, x, y, sampleMm() / viewport_w_mm, kWhite,
             kLegendEdge, 1, rows, columns, static_cast<PLINT>(texts.size()), opts.data(), 1.0, 1.0, 2.0, 0.0,
             text_colors.data(), ctext.data(), box_colors.data(), box_patterns.data(), box_scales.data(),
             box_widths.data(), line_colors.data(), line_styles.data(), line_widths.data(), nullptr, nullptr,
             nullptr, nullptr);
    return {w, h};
  }
};

}  // namespace

void Range::add(double v) {
  if (!std::isfinite(v)) return;
  v = clampHuge(v);
  lo = std::min(lo, v);
  hi = std::max(hi, v);
}

void Range::widenIfFlat() {
  if (hi - lo > 1e-12 * std::max(1.0, std::abs(lo))) return;
  const double d = (lo != 0.0) ? 0.1 * std::abs(lo) : 1.0;
  lo -= d;
  hi += d;
}

Prepared prepare(const std::string& path, const PlotSpec& spec) {
  Prepared p{spec, {}, {}, false, {}};
  p.log_y = !spec.parametric && (spec.y_scale == YScale::Log || (spec.y_scale == YScale::Auto && wantsLog(spec)));
  if (p.log_y) toLog(p.spec);
  // Faint: a noise-like series beside one much smoother (its roughness a tenth or less).
  std::vector<double> rough;
  for (const auto& s : p.spec.series) rough.push_back(roughness(s));
  for (size_t i = 0; i < rough.size(); ++i) {
    bool smoother_other = false;
    for (size_t j = 0; j < rough.size(); ++j) smoother_other = smoother_other || (j != i && rough[j] * 10 < rough[i]);
    p.faint.push_back(rough[i] > kRough && smoother_other);
  }
  setRanges(path, p);
  return p;
}

void setColours() {
  plscmap0n(kFaint0 + kPaletteSize);
  plscol0(kWhite, 255, 255, 255);
  plscol0(kInk, 0, 0, 0);
  plscol0(kGrid, 222, 222, 222);
  plscol0a(kBand, 120, 120, 120, 0.22);
  plscol0(kMarker, 90, 90, 90);
  plscol0(kAxis, 60, 60, 60);
  plscol0(kLegendEdge, 170, 170, 170);
  plscol0(kSpan, 175, 175, 190);
  for (int i = 0; i < kPaletteSize; ++i) {
    plscol0(kPalette0 + i, kPalette[i].r, kPalette[i].g, kPalette[i].b);
    plscol0a(kFaint0 + i, kPalette[i].r, kPalette[i].g, kPalette[i].b, 0.45);
  }
}

namespace {

// Where the frame sits on the page (margins in mm) and the data ranges it shows (equal aspect widens
// one of them to the frame's shape); the legend's place and shape.
struct Placement {
  Range xr, yr;
  double left = 0, right = 0, top = 0, bottom = 0;
  double axis_below = 0;  // the tick labels and x label below the frame
  size_t ytick_w = 1;     // the widest y tick label, in glyphs
  bool legend_right = false;
  int columns = 1, rows = 0;
};

// Ticks and margins: tick and axis labels left and below, the title on top, the legend right of the
// frame (narrow) or below the x label (wide, in as many columns as fit); then equal aspect.
Placement place(const Prepared& p, const Legend& legend, double ch, double page_w, double page_h) {
  const PlotSpec& spec = p.spec;
  Placement f;
  f.xr = p.xr, f.yr = p.yr;
  Range &xr = f.xr, &yr = f.yr;
  // Ticks at nice steps (whole decades on a log axis; one step on both axes of an equal-aspect
  // plot, so the grid is square), labelled by our own formatter so their widths are known.
  size_t xtick_w = 1;
  const auto setTicks = [&] {
    tick_x = {niceStep(xr.hi - xr.lo, kXTicks), std::max(std::abs(xr.lo), std::abs(xr.hi)), false};
    tick_y = {niceStep(yr.hi - yr.lo, kYTicks), std::max(std::abs(yr.lo), std::abs(yr.hi)), p.log_y};
    if (p.log_y) tick_y.step = std::max(1.0, std::round(tick_y.step));
    if (spec.equal_aspect) tick_x.step = tick_y.step = std::max(tick_x.step, tick_y.step);
    f.ytick_w = widestTick(tick_y, yr.lo, yr.hi), xtick_w = widestTick(tick_x, xr.lo, xr.hi);
  };
  setTicks();
  const double cw = kGlyphWidth * ch, gap = 0.8 * ch;
  f.legend_right = !legend.empty() && legend.entryMm() <= kMaxRightLegend * page_w;
  const auto leftMargin = [&] { return 0.6 * ch + (spec.ylabel.empty() ? 0.0 : 2.5 * ch) + f.ytick_w * cw + 0.8 * ch; };
  const auto rightMargin = [&] {
    return f.legend_right ? legend.entryMm() + 1.2 * ch : std::max(1.8 * ch, 0.5 * xtick_w * cw + 0.5 * ch);
  };
  f.left = leftMargin(), f.right = rightMargin();
  f.axis_below = (spec.xlabel.empty() ? 0.0 : 1.8 * ch) + 1.8 * ch;
  f.rows = static_cast<int>(legend.texts.size());
  if (!legend.empty() && !f.legend_right) {
    f.columns = std::clamp(static_cast<int>((page_w - 2 * gap) / legend.entryMm()), 1, f.rows);
    f.rows = (f.rows + f.columns - 1) / f.columns;
  }
  const double legend_below = legend.empty() || f.legend_right ? 0.0 : gap + legend.heightMm(f.rows);
  f.bottom = 1.0 * ch + f.axis_below + legend_below;  // the x label's descenders clear the page's edge
  f.top = spec.title.empty() ? 1.2 * ch : 3.0 * ch;
  // Equal aspect: widen the data to the frame's shape, re-tick (labels may change width), then
  // trim the frame about its middle so a unit is exactly as long along x as along y.
  if (spec.equal_aspect && page_w - f.right - f.left > 0 && page_h - f.top - f.bottom > 0) {
    const PlotWindow w = equalAspect({xr.lo, xr.hi, yr.lo, yr.hi}, page_w - f.right - f.left, page_h - f.top - f.bottom);
    xr = {w.x0, w.x1}, yr = {w.y0, w.y1};
    setTicks();
    f.left = leftMargin(), f.right = rightMargin();
    const double fw = page_w - f.right - f.left, fh = page_h - f.top - f.bottom;
    const double per_x = (xr.hi - xr.lo) / fw, per_y = (yr.hi - yr.lo) / fh;  // data per mm
    if (per_x < per_y) {
      const double cut = 0.5 * (fw - (xr.hi - xr.lo) / per_y);
      f.left += cut, f.right += cut;
    } else {
      const double cut = 0.5 * (fh - (yr.hi - yr.lo) / per_x);
      f.bottom += cut, f.top += cut;
    }
  }
  return f;
}

// The grid underneath, then the layers: spans, faint series, bands, solid series, dashed ones (a
// reference stays visible over a response that tracks it), then the markers on top.
void drawData(const Prepared& p, const Range& xr, const Range& yr, double frame_w, double scale) {
  const PlotSpec& spec = p.spec;
  plcol0(kGrid);
  plwidth(scale);
  plbox("g", tick_x.step, 0, "g", tick_y.step, 0);
  if (!spec.parametric)
    for (const auto& s : spec.spans) drawSpan(s, xr, yr, scale);
  // Points per series: a bucket of two pixel columns keeps its min and max, about one point per
  // pixel column; more points draw the same picture and cost the stroker its time.
  const size_t budget = std::max<size_t>(400, static_cast<size_t>(frame_w / kMmPerPx));
  for (size_t i = 0; i < spec.series.size(); ++i)
    if (p.faint[i]) drawSeries(spec.series[i], true, budget, scale);
  for (const auto& b : spec.bands) drawBand(b, budget);
  for (auto style : {PlotSeries::Style::Solid, PlotSeries::Style::Dashed, PlotSeries::Style::Dotted, PlotSeries::Style::DashDot})
    for (size_t i = 0; i < spec.series.size(); ++i)
      if (!p.faint[i] && spec.series[i].style == style) drawSeries(spec.series[i], false, budget, scale);
  plcol0(kMarker);
  pllsty(2);
  plwidth(1.5 * scale);
  for (double v : spec.vlines) {
    if (!std::isfinite(v) || spec.parametric) continue;
    PLFLT mx[2] = {clampHuge(v), clampHuge(v)}, my[2] = {yr.lo, yr.hi};
    plline(2, mx, my);
  }
  pllsty(1);
}

// The title, centred on the page (it may be wider than the frame), shrunk to fit it down to the tick
// labels' size, and beyond that cut at the end with "…": never cut by the page's edge.
void drawTitle(const std::string& text, double ch, double page_w, double left, double frame_w) {
  const double room = page_w - 1.2 * ch, per_char = kTitleGlyphWidth * ch;
  std::string title = text;
  std::size_t chars = utf8Chars(title);
  const double s = std::clamp(room / (per_char * double(chars)), 1.0, 1.25);
  if (per_char * s * double(chars) > room) {
    const std::size_t keep = static_cast<std::size_t>(std::max(1.0, room / (per_char * s) - 1));
    title = utf8Prefix(title, keep);
    while (!title.empty() && (title.back() == ' ' || title.back() == ',')) title.pop_back();
    title += "…";
  }
  plschr(ch, s);
  plmtex("t", 1.2 * 1.25 / s, (0.5 * page_w - left) / frame_w, 0.5, ("#<bold/>" + plText(title)).c_str());
  plschr(ch, 1.0);
}

}  // namespace

PlotLayout draw(const Prepared& p, int width_px, int height_px) {
  const PlotSpec& spec = p.spec;
  // Lines scale with the picture; text also with the spec's font scale.
  const double scale = std::clamp(std::min(width_px / 800.0, height_px / 450.0), 0.8, 4.0);
  const double text_scale = scale * std::clamp(spec.font_scale, 0.25, 8.0);
  pladv(0);
  const double ch = kCharHeightPx * kMmPerPx * text_scale;
  plschr(ch, 1.0);
  PLFLT page_x0, page_x1, page_y0, page_y1;
  plgspa(&page_x0, &page_x1, &page_y0, &page_y1);
  const double page_w = page_x1 - page_x0, page_h = page_y1 - page_y0;

  // The frame placed, then the data in it.
  const Legend legend(p, text_scale, ch, page_w);
  const Placement f = place(p, legend, ch, page_w, page_h);
  const Range &xr = f.xr, &yr = f.yr;
  plslabelfunc(tickLabel, nullptr);
  const double frame_w = page_w - f.right - f.left, frame_h = page_h - f.top - f.bottom;
  plsvpa(f.left, page_w - f.right, f.bottom, page_h - f.top);
  plwind(xr.lo, xr.hi, yr.lo, yr.hi);
  drawData(p, xr, yr, frame_w, scale);

  // Frame, ticks and labels (y tick labels upright), and the title.
  plcol0(kAxis);
  plwidth(scale);
  plbox("bcnto", tick_x.step, 0, "bcntvo", tick_y.step, 0);
  plcol0(kInk);
  if (!spec.xlabel.empty()) plmtex("b", 3.3, 0.5, 0.5, plText(spec.xlabel).c_str());
  if (!spec.ylabel.empty()) plmtex("l", f.ytick_w * kGlyphWidth + 2.2, 0.5, 0.5, plText(spec.ylabel).c_str());
  if (!spec.title.empty()) drawTitle(spec.title, ch, page_w, f.left, frame_w);

  // Where things are, in pixels from the top-left corner.
  PlotLayout layout;
  layout.log_y = p.log_y;
  layout.x_lo = xr.lo, layout.x_hi = xr.hi, layout.y_lo = yr.lo, layout.y_hi = yr.hi;
  layout.frame = {f.left / kMmPerPx, f.top / kMmPerPx, (page_w - f.right) / kMmPerPx, (page_h - f.bottom) / kMmPerPx};
  if (legend.empty()) return layout;
  // Legend: right of the frame, top-aligned; or below the x label, centred on the page.
  const double gap = 0.8 * ch;
  double lx = 1.0 + gap / frame_w, ly = 0.0;
  if (!f.legend_right) {
    lx = (0.5 * (page_w - f.columns * legend.entryMm()) - f.left) / frame_w;
    ly = 1.0 + (f.axis_below + gap) / frame_h;
  }
  const auto [w, h] = legend.draw(lx, ly, f.rows, f.columns, frame_w);
  const PlotBox& fr = layout.frame;
  const double fw = fr.x1 - fr.x0, fh = fr.y1 - fr.y0;
  layout.legend = {fr.x0 + lx * fw, fr.y0 + ly * fh, fr.x0 + (lx + w) * fw, fr.y0 + (ly + h) * fh};
  return layout;
}

}  // namespace dyn::plot_detail
