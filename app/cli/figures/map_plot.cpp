// A stability/score map through PLplot's C API; see map_plot.h.
// Cells are filled rectangles centred on the grid points (exact, and the same on every device);
// the boundary is plcont's zero level of the field, drawn white under black so it reads on any fill.
#include "app/cli/figures/map_plot.h"

#include <plplot/plplot.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "physics/det/det.h"

namespace dyn::app {
namespace {

// The width of a legend's colour box or line sample, and of the colour bar, as fractions of the page.
constexpr double kSymbolWidth = 0.04, kBarWidth = 0.035;

// cmap0 slots of the map.
enum : PLINT { kPaper = 0, kInk = 1, kStable = 2, kUnstable = 3, kNoValue = 4, kWhiteLine = 5, kFrame = 6 };

int plplotFailed(const char* message) { throw std::runtime_error(std::string("PLplot: ") + message); }

std::string deviceOf(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (auto& c : ext) c = char(std::tolower((unsigned char)c));
  if (ext == ".png") return "pngcairo";
  if (ext == ".svg") return "svg";
  if (ext == ".pdf") return "pdfcairo";
  throw std::runtime_error("map " + path + ": expected a .png, .svg or .pdf file name");
}

// Cell edges: halfway between neighbours, half a step beyond the ends.
std::vector<double> edges(const std::vector<double>& c) {
  std::vector<double> e(c.size() + 1);
  const double step = c.size() > 1 ? c[1] - c[0] : 1.0;
  e.front() = c.front() - step / 2;
  e.back() = c.back() + (c.size() > 1 ? c.back() - c[c.size() - 2] : step) / 2;
  for (std::size_t i = 1; i < c.size(); ++i) e[i] = (c[i - 1] + c[i]) / 2;
  return e;
}

// A perceptually even blue → green → yellow scale (viridis' anchors) for values.
void valueScale() {
  PLFLT pos[] = {0.0, 0.25, 0.5, 0.75, 1.0};
  PLFLT r[] = {68 / 255., 59 / 255., 33 / 255., 94 / 255., 253 / 255.};
  PLFLT g[] = {1 / 255., 82 / 255., 145 / 255., 201 / 255., 231 / 255.};
  PLFLT b[] = {84 / 255., 139 / 255., 140 / 255., 98 / 255., 37 / 255.};
  plscmap1n(256);
  plscmap1l(1, 5, pos, r, g, b, nullptr);
}

void fillCell(double x0, double x1, double y0, double y1) {
  PLFLT px[] = {x0, x1, x1, x0}, py[] = {y0, y0, y1, y1};
  plfill(4, px, py);
}

// The colour bar of a value map at (x, y) from the viewport's top left (its labelled box's corner),
// bar_width wide, 55 % of the viewport high, labelled below; returns the labelled box's width.
double colourBar(const std::string& label, double vmin, double vmax, double x, double y, double bar_width) {
  const char* label_text[] = {label.c_str()};
  PLINT label_opts[] = {PL_COLORBAR_LABEL_BOTTOM};
  const char* axis_opts[] = {"bcvtm"};
  PLFLT ticks[] = {0.0};
  PLINT sub_ticks[] = {0}, n_values[] = {2};
  PLFLT range[] = {vmin, vmax};
  const PLFLT* values_ptr[] = {range};
  PLFLT width = 0, height = 0;
  plcolorbar(&width, &height, PL_COLORBAR_GRADIENT, PL_POSITION_TOP | PL_POSITION_LEFT | PL_POSITION_INSIDE, x, y,
             bar_width, 0.55, kPaper, kFrame, 1, 0, 0, kInk, 0, 1, label_opts, label_text, 1, axis_opts, ticks,
             sub_ticks, n_values, values_ptr);
  return width;
}

// Text as the page will draw it, measured on a throwaway pdfcairo stream of the same size (PLplot
// does not export plstrl; pllegend reports the width it laid out, its text at text_scale × the
// default height whatever plschr says). Widths are fractions of the page's width, heights of its
// height. The driver measures only text it draws: an empty string reports the previous length.
class TextMeter {
 public:
  TextMeter(int width_px, int height_px) : aspect_(double(width_px) / height_px) {
    plgstrm(&page_);
    plmkstrm(&mine_);
    plsdev("pdfcairo");
    plsfnam("/dev/null");
    plspage(72, 72, width_px, height_px, 0, 0);
    plinit();
    pladv(0);
    plvpor(0, 1, 0, 1);
    plwind(0, 1, 0, 1);
    plsstrm(page_);
  }
  ~TextMeter() {
    plsstrm(mine_);
    plend1();
    plsstrm(page_);
  }
  TextMeter(const TextMeter&) = delete;
  TextMeter& operator=(const TextMeter&) = delete;

  // The width of one line of text at character scale `scale`.
  double width(const std::string& text, double scale) {
    return legend({"X" + text}, scale, PL_LEGEND_NONE) - legend({"X"}, scale, PL_LEGEND_NONE);
  }
  // The width of the labelled colour bar at `scale`.
  double colourBar(const std::string& label, double vmin, double vmax, double scale) {
    plsstrm(mine_);
    plschr(0, scale);
    const double w = dyn::app::colourBar(label, vmin, vmax, 0, 0, kBarWidth);
    plsstrm(page_);
    return w;
  }
  // The character height at `scale`, as a fraction of the page's height (X: of its width).
  double charHeight(double scale) { return charMm(scale) / pageMm(false); }
  double charHeightX(double scale) { return charMm(scale) / pageMm(true); }
  // A length measured as a fraction of the page's width, as a fraction of its height.
  double widthToHeight(double w) const { return w * aspect_; }

  // The width pllegend lays out for these entries (all of one kind, none empty) at scale `scale`,
  // drawn as draw() draws the legend.
  double legend(const std::vector<std::string>& texts, double scale, PLINT kind) {
    plsstrm(mine_);
    plschr(0, scale);
    const std::size_t n = texts.size();
    std::vector<const char*> ctexts;
    for (const auto& t : texts) ctexts.push_back(t.c_str());
    std::vector<PLINT> opts(n, kind), colours(n, 1), patterns(n, 0), styles(n, 1);
    std::vector<PLFLT> box_scales(n, 1.1), box_widths(n, 0), line_widths(n, 1);
    PLFLT lw = 0, lh = 0;
    pllegend(&lw, &lh, 0, PL_POSITION_TOP | PL_POSITION_LEFT | PL_POSITION_INSIDE, 0, 0, kSymbolWidth, 0, 1, 1, 0, 0,
             PLINT(n), opts.data(), 0.6, scale, 1.6, 0.0, colours.data(), ctexts.data(), colours.data(),
             patterns.data(), box_scales.data(), box_widths.data(), colours.data(), styles.data(), line_widths.data(),
             nullptr, nullptr, nullptr, nullptr);
    plsstrm(page_);
    return lw;
  }

 private:
  double charMm(double scale) {
    plsstrm(mine_);
    plschr(0, scale);
    PLFLT def = 0, ht = 0;
    plgchr(&def, &ht);
    plsstrm(page_);
    return ht;
  }
  double pageMm(bool x) {
    plsstrm(mine_);
    PLFLT x0 = 0, x1 = 0, y0 = 0, y1 = 0;
    plgspa(&x0, &x1, &y0, &y1);
    plsstrm(page_);
    return x ? x1 - x0 : y1 - y0;
  }

  double aspect_;
  PLINT page_ = 0, mine_ = 0;
};

// A tick step of 1, 2 or 5 × 10^k giving about five intervals over `range`, and the tick labels
// PLplot writes with it (as many decimals as the step needs).
struct Ticks {
  double step = 1;
  std::vector<std::string> labels;
};
Ticks ticksFor(double lo, double hi) {
  Ticks t;
  const double rough = (hi - lo) / 6, decade = det::pow(10.0, std::floor(det::log10(rough)));
  for (double f : {1.0, 2.0, 5.0, 10.0})
    if (f * decade >= rough * (1 - 1e-9)) {
      t.step = f * decade;
      break;
    }
  const int decimals = std::max(0, int(std::ceil(-det::log10(t.step) - 1e-9)));
  for (double k = std::ceil(lo / t.step - 1e-9); k * t.step <= hi + 1e-9 * t.step; k += 1) {
    char b[64];
    std::snprintf(b, sizeof b, "%.*f", decimals, std::abs(k) < 0.5 ? 0.0 : k * t.step);
    t.labels.push_back(b);
  }
  return t;
}

// The character scale at which `text` (width w at scale s) fits in `room`: s, or smaller.
double fitScale(double s, double w, double room) { return w <= room ? s : s * room / w; }

// The cells: a value's colour (values), else stable or not.
void drawCells(const MapPicture& m, const std::vector<double>& ex, const std::vector<double>& ey, double vmin, double vmax) {
  const std::size_t nx = m.xs.size(), ny = m.ys.size();
  const bool values = !m.value.empty();
  for (std::size_t j = 0; j < ny; ++j)
    for (std::size_t i = 0; i < nx; ++i) {
      const std::size_t k = j * nx + i;
      if (values && m.stable[k] && std::isfinite(m.value[k])) plcol1((m.value[k] - vmin) / (vmax - vmin));
      else plcol0(values ? kNoValue : m.stable[k] ? kStable : kUnstable);
      fillCell(ex[i], ex[i + 1], ey[j], ey[j + 1]);
    }

}

// The boundary: the field's zero level, interpolated between grid points (white under ink).
void drawBoundary(const MapPicture& m, double scale) {
  const std::size_t nx = m.xs.size(), ny = m.ys.size();
  if (!m.boundary.empty() && nx > 1 && ny > 1) {
    std::vector<std::vector<PLFLT>> f(nx, std::vector<PLFLT>(ny));
    std::vector<const PLFLT*> rows(nx);
    for (std::size_t i = 0; i < nx; ++i) {
      for (std::size_t j = 0; j < ny; ++j) f[i][j] = m.boundary[j * nx + i];
      rows[i] = f[i].data();
    }
    std::vector<PLFLT> xg(m.xs.begin(), m.xs.end()), yg(m.ys.begin(), m.ys.end());
    PLcGrid grid{xg.data(), yg.data(), nullptr, PLINT(nx), PLINT(ny), 0};
    const PLFLT level[] = {0.0};
    for (auto [colour, width] : {std::pair{kWhiteLine, 5.5}, std::pair{kInk, 2.5}}) {
      plcol0(colour);
      plwidth(width * scale);
      plcont(rows.data(), PLINT(nx), PLINT(ny), 1, PLINT(nx), 1, PLINT(ny), level, 1, pltr1, &grid);
    }
  }
}

// Where the frame sits on the page (fractions of it) and the margin no ink enters.
struct FrameBox {
  double mx, my, fl, fr, fb, ft;
};

// Each axis label centred on its side of the frame, moved (and if need be shrunk) to stay on the
// page; the title across the whole page (it may be wider than the frame).
void drawAxisLabels(const MapPicture& m, TextMeter& meter, double text, double title_scale, const FrameBox& b) {
  const auto [mx, my, fl, fr, fb, ft] = b;
  {
    const double room = 1 - 2 * mx, s = fitScale(text, meter.width(m.xlabel, text), room);
    const double w = meter.width(m.xlabel, s), centre = std::clamp((fl + fr) / 2, mx + w / 2, 1 - mx - w / 2);
    plschr(0, s);
    plmtex("b", 3.3 * text / s, (centre - fl) / (fr - fl), 0.5, m.xlabel.c_str());
  }
  {
    const double room = 1 - 2 * my, s = fitScale(text, meter.widthToHeight(meter.width(m.ylabel, text)), room);
    const double h = meter.widthToHeight(meter.width(m.ylabel, s));
    const double centre = std::clamp((fb + ft) / 2, my + h / 2, 1 - my - h / 2);
    plschr(0, s);
    plmtex("l", (fl - mx) / meter.charHeightX(s) - 1.0, (centre - fb) / (ft - fb), 0.5, m.ylabel.c_str());
  }
  // The title across the whole page (it may be wider than the frame).
  plvpor(0.0, 1.0, 0.0, 1 - my);
  plschr(0, title_scale);
  plmtex("t", -1.3, 0.5, 0.5, m.title.c_str());
}

void draw(const MapPicture& m, int width_px, int height_px) {
  const auto ex = edges(m.xs), ey = edges(m.ys);
  const bool values = !m.value.empty();
  double vmin = INFINITY, vmax = -INFINITY;
  for (std::size_t k = 0; k < m.value.size(); ++k)
    if (m.stable[k] && std::isfinite(m.value[k])) vmin = std::min(vmin, m.value[k]), vmax = std::max(vmax, m.value[k]);
  if (!(vmin <= vmax)) vmin = 0, vmax = 1;
  if (vmax - vmin < 1e-12 * std::max(1.0, std::abs(vmin))) vmin -= 0.5, vmax += 0.5;
  const double wx0 = std::min(ex.front(), ex.back()), wx1 = std::max(ex.front(), ex.back());
  const double wy0 = std::min(ey.front(), ey.back()), wy1 = std::max(ey.front(), ey.back());

  pladv(0);
  TextMeter meter(width_px, height_px);
  // Lines grow with the page; text does already (PLplot's default height follows the page size).
  const double scale = std::clamp(std::min(width_px / 900.0, height_px / 600.0), 0.6, 4.0);
  const double text = 1.05, legend_text = 0.9;
  // A margin of 1.2 % of the page (at least 6 px) that no ink enters.
  const double mx = std::max(6.0 / width_px, 0.012), my = std::max(6.0 / height_px, 0.012);
  const double ch = meter.charHeight(text), chx = meter.charHeightX(text);

  // Legend: the cell kinds shown, then the boundary line.
  std::vector<std::string> texts;
  std::vector<PLINT> opts, boxes, lines, styles;
  auto add = [&](const std::string& t, PLINT opt, PLINT box, PLINT line) {
    texts.push_back(t), opts.push_back(opt), boxes.push_back(box), lines.push_back(line), styles.push_back(1);
  };
  if (!values) add(m.stable_label, PL_LEGEND_COLOR_BOX, kStable, kInk);
  add(values ? m.unstable_label + " (no value)" : m.unstable_label, PL_LEGEND_COLOR_BOX, values ? kNoValue : kUnstable, kInk);
  // The boundary is listed only where it is drawn: where the field changes sign on the grid.
  const bool crosses = std::any_of(m.boundary.begin(), m.boundary.end(), [](double b) { return b > 0; }) &&
                       std::any_of(m.boundary.begin(), m.boundary.end(), [](double b) { return b < 0; });
  if (crosses && m.xs.size() > 1 && m.ys.size() > 1) add(m.boundary_label, PL_LEGEND_LINE, kInk, kInk);

  // The right-hand column holds the legend and the labelled colour bar at their measured widths:
  // each at most 40 % of the page (longer texts are drawn smaller), the frame takes the rest.
  const double max_column = 0.40 - mx;
  auto fitted = [&](auto&& width_at, double& s) {
    double w = width_at(s);
    for (int k = 0; k < 4 && w > max_column; ++k) s *= 0.98 * max_column / w, w = width_at(s);
    return w;
  };
  double legend_scale = legend_text, bar_scale = legend_text;
  double column = fitted([&](double s) {
    double w = 0;
    for (const auto& t : texts) w = std::max(w, meter.legend({t}, s, PL_LEGEND_COLOR_BOX));
    return w;
  }, legend_scale);
  if (values) column = std::max(column, fitted([&](double s) { return meter.colourBar(m.value_label, vmin, vmax, s); }, bar_scale));

  // Ticks and how much room their labels take; then the frame: the title above it, tick labels
  // and axis labels left of and below it, the column right of it.
  const Ticks xt = ticksFor(wx0, wx1), yt = ticksFor(wy0, wy1);
  double ytick_w = 0, xtick_w = 0;
  for (const auto& l : yt.labels) ytick_w = std::max(ytick_w, meter.width(l, text));
  for (const auto& l : xt.labels) xtick_w = std::max(xtick_w, meter.width(l, text));
  const double title_scale = fitScale(1.15, meter.width(m.title, 1.15), 1 - 2 * mx);
  const double fl = mx + ytick_w + 2.9 * chx, fr = 1 - mx - column - 0.5 * xtick_w - 1.5 * chx;
  const double fb = my + 4.6 * ch, ft = 1 - my - 2.6 * meter.charHeight(title_scale);
  plvpor(fl, fr, fb, ft);
  plwind(wx0, wx1, wy0, wy1);

  // Plain tick labels (no "×10⁻²" factor that a reader has to find).
  plsxax(8, 0);
  plsyax(8, 0);
  plschr(0, text);

  drawCells(m, ex, ey, vmin, vmax);
  drawBoundary(m, scale);

  // Frame, ticks at the measured steps, labels.
  plwidth(1.0 * scale);
  plcol0(kFrame);
  plbox("bcnts", xt.step, 0, "bcntsv", yt.step, 0);
  plcol0(kInk);
  drawAxisLabels(m, meter, text, title_scale, {mx, my, fl, fr, fb, ft});

  // The legend at the top of the right-hand column.
  std::vector<const char*> ctexts;
  for (const auto& t : texts) ctexts.push_back(t.c_str());
  std::vector<PLINT> text_colours(texts.size(), kInk), patterns(texts.size(), 0);
  std::vector<PLFLT> box_scales(texts.size(), 1.1), box_widths(texts.size(), 0), line_widths(texts.size(), 2.5 * scale);
  PLFLT lw, lh;
  plvpor(1 - mx - column, 1 - mx, fb, ft);
  plwind(0, 1, 0, 1);
  plschr(0, legend_scale);
  pllegend(&lw, &lh, PL_LEGEND_BACKGROUND, PL_POSITION_TOP | PL_POSITION_LEFT | PL_POSITION_INSIDE, 0.0, 0.0, kSymbolWidth / column,
           kPaper, kFrame, 1, 0, 0, PLINT(texts.size()), opts.data(), 0.6, legend_scale, 1.6, 0.0, text_colours.data(),
           ctexts.data(), boxes.data(), patterns.data(), box_scales.data(), box_widths.data(), lines.data(),
           styles.data(), line_widths.data(), nullptr, nullptr, nullptr, nullptr);
  if (values) {
    // The colour bar under the legend, labelled with the metric and its unit, centred in the column.
    plschr(0, bar_scale);
    const double box = meter.colourBar(m.value_label, vmin, vmax, bar_scale);
    colourBar(m.value_label, vmin, vmax, (1 - box / column) / 2, lh + 0.08, kBarWidth / column);
  }
}

// pdfcairo stamps the wall-clock time into /CreationDate: overwrite its digits with a fixed date
// (same length, so the cross-reference offsets stay right).
void pinPdfDate(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  const std::string key = "/CreationDate (D:";
  const std::size_t at = bytes.find(key);
  if (at == std::string::npos) return;
  for (std::size_t k = at + key.size(), n = 0; k < bytes.size() && n < 14 && std::isdigit((unsigned char)bytes[k]); ++k, ++n)
    bytes[k] = "19800101000000"[n];
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
}

}  // namespace

void writeMapPicture(const std::string& path, const MapPicture& m, int width_px, int height_px) {
  const std::string device = deviceOf(path);
  if (m.xs.empty() || m.ys.empty() || m.stable.size() != m.xs.size() * m.ys.size())
    throw std::runtime_error("map " + path + ": the grid and its cells do not match");
  const std::string tmp = path + ".tmp";
  if (std::FILE* f = std::fopen(tmp.c_str(), "wb")) std::fclose(f);  // PLplot would exit() on an unwritable file
  else throw std::runtime_error("map " + path + ": cannot write " + tmp);
  {
    PLINT previous, mine;
    plgstrm(&previous);
    plmkstrm(&mine);
    try {
      plsexit(plplotFailed);
      plsdev(device.c_str());
      plsfnam(tmp.c_str());
      plspage(72, 72, width_px, height_px, 0, 0);
      plsfam(0, 0, 0);
      plscol0(kPaper, 255, 255, 255);
      plscol0(kInk, 0, 0, 0);
      plscol0(kStable, 146, 197, 222);    // light blue
      plscol0(kUnstable, 244, 165, 130);  // light orange-red
      plscol0(kNoValue, 200, 200, 200);
      plscol0(kWhiteLine, 255, 255, 255);
      plscol0(kFrame, 60, 60, 60);
      valueScale();
      plinit();
      draw(m, width_px, height_px);
      plend1();
      plsstrm(previous);
    } catch (const std::exception& e) {
      plend1();
      plsstrm(previous);
      std::remove(tmp.c_str());
      throw std::runtime_error("map " + path + ": " + e.what());
    }
  }
  if (device == "pdfcairo") pinPdfDate(tmp);
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw std::runtime_error("map " + path + ": cannot rename " + tmp + ": " + ec.message());
  }
}

}  // namespace dyn::app
