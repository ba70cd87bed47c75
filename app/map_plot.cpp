// A stability/score map through PLplot's C API; see map_plot.h.
// Cells are filled rectangles centred on the grid points (exact, and the same on every device);
// the boundary is plcont's zero level of the field, drawn white under black so it reads on any fill.
#include "app/map_plot.h"

#include <plplot/plplot.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

namespace dyn::app {
namespace {

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

void draw(const MapPicture& m, int width_px, int height_px) {
  const std::size_t nx = m.xs.size(), ny = m.ys.size();
  const auto ex = edges(m.xs), ey = edges(m.ys);
  const bool values = !m.value.empty();
  double vmin = INFINITY, vmax = -INFINITY;
  for (std::size_t k = 0; k < m.value.size(); ++k)
    if (m.stable[k] && std::isfinite(m.value[k])) vmin = std::min(vmin, m.value[k]), vmax = std::max(vmax, m.value[k]);
  if (!(vmin <= vmax)) vmin = 0, vmax = 1;
  if (vmax - vmin < 1e-12 * std::max(1.0, std::abs(vmin))) vmin -= 0.5, vmax += 0.5;

  pladv(0);
  const double scale = std::clamp(std::min(width_px / 900.0, height_px / 600.0), 0.6, 4.0);
  plschr(0, 1.05 * scale);
  // The frame on the left, the legend (and colour bar) in a column on the right.
  plvpor(0.10, 0.64, 0.12, 0.90);
  plwind(std::min(ex.front(), ex.back()), std::max(ex.front(), ex.back()), std::min(ey.front(), ey.back()),
         std::max(ey.front(), ey.back()));

  // Plain tick labels (no "×10⁻²" factor that a reader has to find).
  plsxax(8, 0);
  plsyax(8, 0);

  // The cells.
  for (std::size_t j = 0; j < ny; ++j)
    for (std::size_t i = 0; i < nx; ++i) {
      const std::size_t k = j * nx + i;
      if (values && m.stable[k] && std::isfinite(m.value[k])) plcol1((m.value[k] - vmin) / (vmax - vmin));
      else plcol0(values ? kNoValue : m.stable[k] ? kStable : kUnstable);
      fillCell(ex[i], ex[i + 1], ey[j], ey[j + 1]);
    }

  // The boundary: the field's zero level, interpolated between grid points.
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

  // Frame, ticks, labels.
  plwidth(1.0 * scale);
  plcol0(kFrame);
  plbox("bcnts", 0, 0, "bcntsv", 0, 0);
  plcol0(kInk);
  pllab(m.xlabel.c_str(), m.ylabel.c_str(), "");
  // The title across the whole page (it may be wider than the frame).
  plvpor(0.0, 1.0, 0.0, 0.96);
  plschr(0, 1.15 * scale);
  plmtex("t", 0.0, 0.5, 0.5, m.title.c_str());
  plschr(0, 1.05 * scale);

  // Legend: the cell kinds shown, then the boundary line.
  std::vector<std::string> texts;
  std::vector<PLINT> opts, boxes, lines, styles;
  auto add = [&](const std::string& t, PLINT opt, PLINT box, PLINT line) {
    texts.push_back(t), opts.push_back(opt), boxes.push_back(box), lines.push_back(line), styles.push_back(1);
  };
  if (!values) add(m.stable_label, PL_LEGEND_COLOR_BOX, kStable, kInk);
  add(values ? m.unstable_label + " (no value)" : m.unstable_label, PL_LEGEND_COLOR_BOX, values ? kNoValue : kUnstable, kInk);
  if (!m.boundary.empty()) add(m.boundary_label, PL_LEGEND_LINE, kInk, kInk);
  std::vector<const char*> ctexts;
  for (const auto& t : texts) ctexts.push_back(t.c_str());
  std::vector<PLINT> text_colours(texts.size(), kInk), patterns(texts.size(), 0);
  std::vector<PLFLT> box_scales(texts.size(), 1.1), box_widths(texts.size(), 0), line_widths(texts.size(), 2.5 * scale);
  PLFLT lw, lh;
  plvpor(0.655, 0.995, 0.12, 0.90);
  plwind(0, 1, 0, 1);
  plschr(0, 0.9 * scale);
  pllegend(&lw, &lh, PL_LEGEND_BACKGROUND, PL_POSITION_TOP | PL_POSITION_LEFT | PL_POSITION_INSIDE, 0.02, 0.0, 0.12,
           kPaper, kFrame, 1, 0, 0, PLINT(texts.size()), opts.data(), 0.6, 1.0, 1.6, 0.0, text_colours.data(),
           ctexts.data(), boxes.data(), patterns.data(), box_scales.data(), box_widths.data(), lines.data(),
           styles.data(), line_widths.data(), nullptr, nullptr, nullptr, nullptr);
  if (values) {
    // The colour bar under the legend, labelled with the metric and its unit.
    const char* label_text[] = {m.value_label.c_str()};
    PLINT label_opts[] = {PL_COLORBAR_LABEL_BOTTOM};
    const char* axis_opts[] = {"bcvtm"};
    PLFLT ticks[] = {0.0};
    PLINT sub_ticks[] = {0}, n_values[] = {2};
    PLFLT range[] = {vmin, vmax};
    const PLFLT* values_ptr[] = {range};
    PLFLT cw, chh;
    plcolorbar(&cw, &chh, PL_COLORBAR_GRADIENT, PL_POSITION_TOP | PL_POSITION_LEFT | PL_POSITION_INSIDE, 0.08,
               lh + 0.08, 0.12, 0.55, kPaper, kFrame, 1, 0, 0, kInk, 0, 1, label_opts, label_text, 1, axis_opts, ticks,
               sub_ticks, n_values, values_ptr);
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
