// Response plots with PLplot's C API; see plot.h.
// One PLplot stream per plot (PLplot keeps global state, so a mutex serialises callers), sized in
// pixels at 72 dpi, white background, light grid, Okabe–Ito colours; the legend goes right of the
// frame, or (when wide) inside it in the corner the data leave emptiest.
// Every number PLplot sees is finite: the data are split into finite runs before drawing.
#include "grading/plot.h"

#include <plplot/plplot.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <stdexcept>

#include "labs/file_write.h"

namespace dyn {
namespace {

constexpr double kDpi = 72.0;          // the cairo devices' own resolution: 1 px = 1 pt
constexpr double kMmPerPx = 25.4 / kDpi;
constexpr size_t kMaxPoints = 2000;    // per series; longer ones keep each bucket's min and max
constexpr double kHuge = 1e100;        // |values| beyond this are clamped (PLplot needs finite spans)
constexpr double kCharHeightPx = 9.0;  // PLplot character height: ~12 px tick labels, 15 px title
constexpr double kGlyphWidth = 0.7;    // a generous average glyph width, in character heights
constexpr double kMaxOutsideLegend = 0.3;  // wider legends (fraction of the page) go inside the frame
constexpr double kXTicks = 8, kYTicks = 6;  // about this many tick intervals per axis

// cmap0 slots: fixed colours first, then the series palette.
enum Col : PLINT { kWhite = 0, kInk = 1, kGrid = 2, kBand = 3, kMarker = 4, kAxis = 5, kLegendEdge = 6, kPalette0 = 8 };
struct Rgb { int r, g, b; };
// Okabe & Ito's colour-blind-safe palette, ordered for contrast on white (yellow left out).
constexpr Rgb kPalette[] = {{0, 114, 178}, {213, 94, 0},   {0, 158, 115}, {204, 121, 167},
                            {230, 159, 0}, {86, 180, 233}, {0, 0, 0}};
constexpr int kPaletteSize = sizeof kPalette / sizeof kPalette[0];

std::mutex plplot_mutex;

[[noreturn]] void fail(const std::string& path, const std::string& why) {
  throw std::runtime_error("writePlot " + path + ": " + why);
}

// PLplot's fatal errors would call exit(); turn them into exceptions instead.
int throwOnPlplotExit(const char* message) { throw std::runtime_error(std::string("PLplot: ") + message); }

// PLplot reads '#' as its escape character; "##" is a literal '#'.
std::string plText(const std::string& s) {
  std::string out;
  for (char c : s) out += (c == '#') ? std::string("##") : std::string(1, c);
  return out;
}

std::string deviceFor(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".png") return "pngcairo";
  if (ext == ".svg") return "svg";
  if (ext == ".pdf") return "pdfcairo";
  fail(path, "unsupported extension \"" + ext + "\" (use .png, .svg or .pdf)");
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

struct Range {
  double lo = INFINITY, hi = -INFINITY;
  void add(double v) {
    if (!std::isfinite(v)) return;
    v = clampHuge(v);
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool empty() const { return lo > hi; }
  // A degenerate range becomes a small symmetric one around its value.
  void widenIfFlat() {
    if (hi - lo > 1e-12 * std::max(1.0, std::abs(lo))) return;
    const double d = (lo != 0.0) ? 0.1 * std::abs(lo) : 1.0;
    lo -= d;
    hi += d;
  }
};

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
  const double raw = span / target, mag = std::pow(10.0, std::floor(std::log10(raw))), r = raw / mag;
  return (r < 1.414 ? 1.0 : r < 3.162 ? 2.0 : r < 7.071 ? 5.0 : 10.0) * mag;
}

// Tick labels with just enough decimals for the step; "%g" for very large or small numbers.
struct TickFormat {
  double step = 1, max_abs = 1;
  std::string format(double v) const {
    char buf[64];
    if (std::abs(v) < 1e-9 * step) v = 0.0;  // no "-0.00"
    if (max_abs >= 1e6 || step < 1e-4) {
      std::snprintf(buf, sizeof buf, "%.3g", v);
    } else {
      const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
      std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    }
    return buf;
  }
};
TickFormat tick_x, tick_y;  // read by the label callback (under plplot_mutex)

void tickLabel(PLINT axis, PLFLT value, char* label, PLINT length, PLPointer) {
  const std::string s = (axis == PL_X_AXIS ? tick_x : tick_y).format(value);
  std::snprintf(label, static_cast<size_t>(length), "%s", s.c_str());
}

// Longest tick label on an axis (for the margin that has to hold it).
size_t widestTick(const TickFormat& f, double lo, double hi) {
  size_t w = 1;
  const double first = std::ceil(lo / f.step) * f.step;
  for (int k = 0; k < 100 && first + k * f.step <= hi + 1e-9 * f.step; ++k)
    w = std::max(w, f.format(first + k * f.step).size());
  return w;
}

// UTF-8 characters in s (for width estimates).
size_t glyphs(const std::string& s) {
  return static_cast<size_t>(std::count_if(s.begin(), s.end(), [](unsigned char c) { return (c & 0xC0) != 0x80; }));
}

void validate(const std::string& path, const PlotSpec& spec) {
  for (const auto& s : spec.series) {
    if (s.x.empty()) fail(path, "series \"" + s.label + "\" is empty");
    if (s.x.size() != s.y.size())
      fail(path, "series \"" + s.label + "\" has " + std::to_string(s.x.size()) + " x values but " +
                     std::to_string(s.y.size()) + " y values");
  }
  for (const auto& b : spec.bands) {
    if (b.x.empty()) fail(path, "band \"" + b.label + "\" is empty");
    if (b.lo.size() != b.x.size() || b.hi.size() != b.x.size())
      fail(path, "band \"" + b.label + "\" has x, lo and hi of different lengths");
  }
  if (spec.series.empty() && spec.bands.empty()) fail(path, "nothing to plot (no series, no bands)");
}

// Keeps PLplot's current stream as it was: a fresh stream for this plot, ended on scope exit.
class Stream {
 public:
  Stream() {
    plgstrm(&previous_);
    plmkstrm(&mine_);
  }
  ~Stream() {
    plsstrm(mine_);
    plend1();
    plsstrm(previous_);
  }

 private:
  PLINT previous_ = 0, mine_ = 0;
};

void setColours() {
  plscol0(kWhite, 255, 255, 255);
  plscol0(kInk, 0, 0, 0);
  plscol0(kGrid, 222, 222, 222);
  plscol0a(kBand, 120, 120, 120, 0.22);
  plscol0(kMarker, 90, 90, 90);
  plscol0(kAxis, 60, 60, 60);
  plscol0(kLegendEdge, 170, 170, 170);
  for (int i = 0; i < kPaletteSize; ++i) plscol0(kPalette0 + i, kPalette[i].r, kPalette[i].g, kPalette[i].b);
}

PLINT seriesColour(int color) { return kPalette0 + ((color % kPaletteSize) + kPaletteSize) % kPaletteSize; }
PLINT seriesStyle(PlotSeries::Style s) { return s == PlotSeries::Style::Dashed ? 3 : 1; }

void drawBand(const PlotBand& b) {
  plcol0(kBand);
  const auto ok = [&](size_t i) { return std::isfinite(b.x[i]) && std::isfinite(b.lo[i]) && std::isfinite(b.hi[i]); };
  for (auto [s, e] : runs(b.x.size(), ok)) {
    // Polygon: along hi forwards, back along lo.
    std::vector<PLFLT> px, py;
    for (size_t i = s; i < e; ++i) px.push_back(clampHuge(b.x[i])), py.push_back(clampHuge(b.hi[i]));
    for (size_t i = e; i-- > s;) px.push_back(clampHuge(b.x[i])), py.push_back(clampHuge(b.lo[i]));
    if (e - s == 1) {  // a single sample: a hairline
      pllsty(1);
      plline(2, px.data(), py.data());
    } else {
      plfill(static_cast<PLINT>(px.size()), px.data(), py.data());
    }
  }
}

void drawSeries(const PlotSeries& s, size_t budget, double scale) {
  plcol0(seriesColour(s.color));
  pllsty(seriesStyle(s.style));
  plwidth(2.0 * scale);
  const auto ok = [&](size_t i) { return std::isfinite(s.x[i]) && std::isfinite(s.y[i]); };
  for (auto [b, e] : runs(s.x.size(), ok)) {
    std::vector<PLFLT> px, py;
    appendThinned(s.x, s.y, b, e, std::max<size_t>(4, budget * (e - b) / s.x.size()), px, py);
    for (auto& v : px) v = clampHuge(v);
    for (auto& v : py) v = clampHuge(v);
    if (px.size() == 1) {
      plpoin(1, px.data(), py.data(), 17);  // an isolated finite sample: a dot
    } else {
      plline(static_cast<PLINT>(px.size()), px.data(), py.data());
    }
  }
  pllsty(1);
}

// Axis ranges from the finite data and the markers; x is tight, y gets 5% headroom. A run that is
// NaN from the start still gets its time axis (and y in [-1, 1]).
std::pair<Range, Range> dataRanges(const std::string& path, const PlotSpec& spec) {
  Range xr, yr;
  for (const auto& s : spec.series)
    for (size_t i = 0; i < s.x.size(); ++i)
      if (std::isfinite(s.x[i])) xr.add(s.x[i]), yr.add(s.y[i]);
  for (const auto& b : spec.bands)
    for (size_t i = 0; i < b.x.size(); ++i)
      if (std::isfinite(b.x[i])) xr.add(b.x[i]), yr.add(b.lo[i]), yr.add(b.hi[i]);
  for (double v : spec.vlines) xr.add(v);
  if (xr.empty()) fail(path, "no finite x values to plot");
  if (yr.empty()) yr = {0.0, 0.0};
  xr.widenIfFlat();
  yr.widenIfFlat();
  // A marker on the last sample (a run that stopped) would hide in the frame: leave it some room.
  for (double v : spec.vlines)
    if (std::isfinite(v) && xr.hi - v < 0.01 * (xr.hi - xr.lo)) xr.hi = v + 0.03 * (xr.hi - xr.lo);
  // An x range ending just short of a tick (t = 0 … 3.999 s) is stretched to it (4.0 s is labelled).
  const double span = xr.hi - xr.lo, step = niceStep(span, kXTicks);
  const double lo = std::floor(xr.lo / step + 1e-9) * step, hi = std::ceil(xr.hi / step - 1e-9) * step;
  if (xr.lo - lo < 0.02 * span) xr.lo = lo;
  if (hi - xr.hi < 0.02 * span) xr.hi = hi;
  const double pad = 0.05 * (yr.hi - yr.lo);
  return {xr, {yr.lo - pad, yr.hi + pad}};
}

// The legend: bands (filled boxes), series (line samples), then the markers, in spec order.
struct Legend {
  std::vector<std::string> texts;
  std::vector<PLINT> opts, text_colors, box_colors, box_patterns, line_colors, line_styles;
  std::vector<PLFLT> box_scales, box_widths, line_widths;

  double scale;
  Legend(const PlotSpec& spec, double scale) : scale(scale) {
    for (const auto& b : spec.bands)
      if (!b.label.empty()) add(b.label, PL_LEGEND_COLOR_BOX, kBand, kInk, 1);
    for (const auto& s : spec.series)
      if (!s.label.empty()) add(s.label, PL_LEGEND_LINE, kInk, seriesColour(s.color), seriesStyle(s.style));
    if (!spec.vlines.empty() && !spec.vline_label.empty()) add(spec.vline_label, PL_LEGEND_LINE, kInk, kMarker, 2);
  }
  void add(const std::string& text, PLINT opt, PLINT box, PLINT line, PLINT style) {
    texts.push_back(plText(text));
    opts.push_back(opt);
    text_colors.push_back(kInk);
    box_colors.push_back(box);
    box_patterns.push_back(0);
    box_scales.push_back(0.9);
    box_widths.push_back(0.0);
    line_colors.push_back(line);
    line_styles.push_back(style);
    line_widths.push_back(2.0 * scale);
  }
  bool empty() const { return texts.empty(); }
  // Estimated size in mm for character height ch (PLplot only measures while it draws).
  double sampleMm(double ch) const { return 4.5 * ch; }
  double widthMm(double ch) const {
    size_t chars = 0;
    for (const auto& t : texts) chars = std::max(chars, glyphs(t));
    return empty() ? 0.0 : sampleMm(ch) + 2.5 * ch + chars * kGlyphWidth * ch + 1.5 * ch;
  }
  double heightMm(double ch) const { return empty() ? 0.0 : (2.0 * texts.size() + 0.6) * ch; }

  // position/x/y as pllegend takes them; the viewport must be set.
  void draw(PLINT position, double x, double y, bool boxed, double ch, double viewport_w_mm) const {
    std::vector<const char*> ctext;
    for (const auto& t : texts) ctext.push_back(t.c_str());
    const PLINT opt = PL_LEGEND_BACKGROUND | (boxed ? PL_LEGEND_BOUNDING_BOX : 0);
    PLFLT w, h;
    pllegend(&w, &h, opt, position, x, y, sampleMm(ch) / viewport_w_mm, kWhite, kLegendEdge, 1, 0, 0,
             static_cast<PLINT>(texts.size()), opts.data(), 1.0, 1.0, 2.0, 0.0, text_colors.data(), ctext.data(),
             box_colors.data(), box_patterns.data(), box_scales.data(), box_widths.data(), line_colors.data(),
             line_styles.data(), line_widths.data(), nullptr, nullptr, nullptr, nullptr);
  }
};

// For a legend inside the frame: the corner (top right, top left, bottom right, bottom left) whose
// box of fw × fh (fractions of the frame) covers the fewest points along the series.
PLINT emptiestCorner(const PlotSpec& spec, const Range& xr, const Range& yr, double fw, double fh) {
  const PLINT corners[] = {PL_POSITION_TOP | PL_POSITION_RIGHT, PL_POSITION_TOP | PL_POSITION_LEFT,
                           PL_POSITION_BOTTOM | PL_POSITION_RIGHT, PL_POSITION_BOTTOM | PL_POSITION_LEFT};
  size_t hits[4] = {0, 0, 0, 0};
  const auto count = [&](double x, double y) {
    const double u = (x - xr.lo) / (xr.hi - xr.lo), v = (y - yr.lo) / (yr.hi - yr.lo);
    const bool right = u > 1 - fw, left = u < fw, top = v > 1 - fh, bottom = v < fh;
    hits[0] += top && right, hits[1] += top && left, hits[2] += bottom && right, hits[3] += bottom && left;
  };
  for (const auto& s : spec.series) {
    const auto ok = [&](size_t i) { return std::isfinite(s.x[i]) && std::isfinite(s.y[i]); };
    for (auto [b, e] : runs(s.x.size(), ok))
      for (size_t i = b; i < e; ++i)
        for (int k = 0; k < (i + 1 < e ? 8 : 1); ++k) {  // also points along each segment
          const double f = k / 8.0;
          count(s.x[i] + f * (i + 1 < e ? s.x[i + 1] - s.x[i] : 0), s.y[i] + f * (i + 1 < e ? s.y[i + 1] - s.y[i] : 0));
        }
  }
  return corners[std::min_element(hits, hits + 4) - hits];
}

// Two fixes to PLplot's files, both byte-length neutral or header-only: the svg device sizes the
// picture in points (say pixels, to match the PNG); pdfcairo stamps the creation date (pin it to
// 1980-01-01 so the PDF is deterministic too; same length, so the xref offsets stay valid).
void fixupFile(std::string& text, const std::string& device, int width_px, int height_px) {
  if (device == "svg") {
    for (auto [key, px] : {std::pair{"width=\"", width_px}, std::pair{"height=\"", height_px}}) {
      const std::string from = key + std::to_string(px) + "pt\"", to = key + std::to_string(px) + "px\"";
      const size_t at = text.find(from);
      if (at != std::string::npos && at < 1024) text.replace(at, from.size(), to);
    }
  } else if (device == "pdfcairo") {
    const std::string key = "/CreationDate (D:", fixed = "19800101000000";
    const size_t at = text.find(key);
    if (at != std::string::npos && at + key.size() + fixed.size() <= text.size() &&
        std::all_of(text.begin() + at + key.size(), text.begin() + at + key.size() + fixed.size(), [](unsigned char c) { return std::isdigit(c) != 0; }))
      text.replace(at + key.size(), fixed.size(), fixed);
  }
}

// PLplot cannot report a failed write (its drivers ignore fwrite/fclose results), so its file is
// checked instead: complete from signature to end marker, or it was cut short.
bool completeFile(const std::string& text, const std::string& device) {
  const auto trimmed = [&] {
    std::size_t end = text.find_last_not_of(" \t\r\n");
    return end == std::string::npos ? std::string() : text.substr(0, end + 1);
  };
  if (device == "pngcairo")  // signature ... IEND chunk (length 0, type, CRC)
    return text.size() >= 20 && text.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0 &&
           text.compare(text.size() - 12, 12, std::string("\0\0\0\0IEND\xae\x42\x60\x82", 12)) == 0;
  if (device == "pdfcairo") {
    const std::string t = trimmed();
    return text.compare(0, 5, "%PDF-") == 0 && t.size() >= 5 && t.compare(t.size() - 5, 5, "%%EOF") == 0;
  }
  const std::string t = trimmed();
  return t.size() >= 6 && t.compare(t.size() - 6, 6, "</svg>") == 0;
}

// Everything PLplot draws for one plot, on the current (fresh, initialised) stream.
// scale: text and line widths relative to an 800 × 450 picture.
void drawPlot(const PlotSpec& spec, const Range& xr, const Range& yr, double scale) {
  pladv(0);
  const double ch = kCharHeightPx * kMmPerPx * scale;
  plschr(ch, 1.0);
  PLFLT page_x0, page_x1, page_y0, page_y1;
  plgspa(&page_x0, &page_x1, &page_y0, &page_y1);
  const double page_w = page_x1 - page_x0, page_h = page_y1 - page_y0;

  // Ticks at nice steps, labelled by our own formatter so their widths are known.
  tick_x = {niceStep(xr.hi - xr.lo, kXTicks), std::max(std::abs(xr.lo), std::abs(xr.hi))};
  tick_y = {niceStep(yr.hi - yr.lo, kYTicks), std::max(std::abs(yr.lo), std::abs(yr.hi))};
  plslabelfunc(tickLabel, nullptr);
  const size_t ytick_w = widestTick(tick_y, yr.lo, yr.hi), xtick_w = widestTick(tick_x, xr.lo, xr.hi);

  // Margins in mm: tick and axis labels left and below, the title on top, a short legend on the
  // right (a wide one goes inside the frame instead).
  const Legend legend(spec, scale);
  const double cw = kGlyphWidth * ch;
  const bool legend_outside = !legend.empty() && legend.widthMm(ch) <= kMaxOutsideLegend * page_w;
  const double left = 0.6 * ch + (spec.ylabel.empty() ? 0.0 : 2.5 * ch) + ytick_w * cw + 0.8 * ch;
  const double bottom = 0.6 * ch + (spec.xlabel.empty() ? 0.0 : 1.8 * ch) + 1.8 * ch;
  const double top = spec.title.empty() ? 1.2 * ch : 3.0 * ch;
  const double right = legend_outside ? legend.widthMm(ch) + 1.2 * ch : std::max(1.8 * ch, 0.5 * xtick_w * cw + 0.5 * ch);
  plsvpa(left, page_w - right, bottom, page_h - top);
  plwind(xr.lo, xr.hi, yr.lo, yr.hi);
  const double frame_w = page_w - right - left, frame_h = page_h - top - bottom;

  // Grid underneath everything.
  plcol0(kGrid);
  plwidth(scale);
  plbox("g", tick_x.step, 0, "g", tick_y.step, 0);

  // Bands, then solid series, then dashed ones (a reference stays visible over a response that
  // tracks it), then the markers on top.
  for (const auto& b : spec.bands) drawBand(b);
  for (const auto& s : spec.series)
    if (s.style == PlotSeries::Style::Solid) drawSeries(s, kMaxPoints, scale);
  for (const auto& s : spec.series)
    if (s.style == PlotSeries::Style::Dashed) drawSeries(s, kMaxPoints, scale);
  plcol0(kMarker);
  pllsty(2);
  plwidth(1.5 * scale);
  for (double v : spec.vlines) {
    if (!std::isfinite(v)) continue;
    PLFLT mx[2] = {clampHuge(v), clampHuge(v)}, my[2] = {yr.lo, yr.hi};
    plline(2, mx, my);
  }
  pllsty(1);

  // Frame, ticks and labels (y tick labels upright).
  plcol0(kAxis);
  plwidth(scale);
  plbox("bcnto", tick_x.step, 0, "bcntvo", tick_y.step, 0);
  plcol0(kInk);
  if (!spec.xlabel.empty()) plmtex("b", 3.3, 0.5, 0.5, plText(spec.xlabel).c_str());
  if (!spec.ylabel.empty()) plmtex("l", ytick_w * kGlyphWidth + 2.2, 0.5, 0.5, plText(spec.ylabel).c_str());
  if (!spec.title.empty()) {
    plschr(ch, 1.25);
    plmtex("t", 1.2, 0.5, 0.5, ("#<bold/>" + plText(spec.title)).c_str());
    plschr(ch, 1.0);
  }

  // Legend: right of the frame, top-aligned; or inside it, in the emptiest corner.
  if (legend.empty()) return;
  if (legend_outside) {
    legend.draw(PL_POSITION_LEFT | PL_POSITION_TOP | PL_POSITION_INSIDE, 1.0 + 0.8 * ch / frame_w, 0.0, false, ch, frame_w);
  } else {
    const double gap = 0.6 * ch;
    const double fw = (legend.widthMm(ch) + gap) / frame_w, fh = (legend.heightMm(ch) + gap) / frame_h;
    const PLINT corner = emptiestCorner(spec, xr, yr, fw, fh);
    legend.draw(PL_POSITION_INSIDE | corner, gap / frame_w, gap / frame_h, true, ch, frame_w);
  }
}

}  // namespace

void writePlot(const std::string& path, const PlotSpec& spec, int width_px, int height_px) {
  const std::string device = deviceFor(path);
  validate(path, spec);
  if (width_px < 100 || height_px < 100 || width_px > 10000 || height_px > 10000)
    fail(path, "size " + std::to_string(width_px) + "x" + std::to_string(height_px) + " is out of range");
  const auto [xr, yr] = dataRanges(path, spec);

  // PLplot writes to a scratch file (it would exit() if it could not open one: check first).
  const std::string scratch = path + ".plplot";
  if (std::FILE* f = std::fopen(scratch.c_str(), "wb")) {
    std::fclose(f);
  } else {
    fail(path, std::string("cannot write ") + scratch + ": " + std::strerror(errno));
  }

  // One fresh PLplot stream: device, file, size in pixels, colours; ended (file closed) on scope exit.
  {
    std::lock_guard<std::mutex> lock(plplot_mutex);
    try {
      plsexit(throwOnPlplotExit);
      Stream stream;
      plsdev(device.c_str());
      plsfnam(scratch.c_str());
      plspage(kDpi, kDpi, width_px, height_px, 0, 0);
      plsfam(0, 0, 0);
      setColours();
      plinit();
      drawPlot(spec, xr, yr, std::clamp(std::min(width_px / 800.0, height_px / 450.0), 0.8, 4.0));
    } catch (const std::exception& e) {
      std::remove(scratch.c_str());
      fail(path, e.what());
    }
  }

  // Read back, fix up, check it is whole, and publish it through the checked writer.
  std::ifstream in(scratch, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const bool read_ok = !in.bad();
  in.close();
  std::remove(scratch.c_str());
  if (!read_ok) fail(path, "cannot read back " + scratch);
  if (writeFaultInjected(std::filesystem::path(path).filename().string())) text.resize(text.size() / 2);
  if (!completeFile(text, device))
    fail(path, text.empty() ? "PLplot wrote nothing" : "PLplot's output is incomplete (" + std::to_string(text.size()) +
                                                            " bytes; is the disk full?)");
  fixupFile(text, device, width_px, height_px);
  try {
    writeFileChecked(path, text);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("writePlot: ") + e.what());
  }
}

}  // namespace dyn
