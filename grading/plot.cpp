// Response plots with PLplot's C API; see plot.h. This half owns the PLplot stream and the file:
// one stream per plot (PLplot keeps global state, so a mutex serialises callers), drawn by
// plot_draw.cpp; a PNG on our own cairo surface and encoded in memory, an SVG or PDF written by
// PLplot to a scratch file; each checked whole, fixed up and published atomically.
#include "grading/plot.h"

#include <cairo.h>
#include <plplot/plplot.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <stdexcept>
#include <string_view>

#include <zlib.h>

#include "grading/plot_draw.h"
#include "labs/file_write.h"

namespace dyn {
namespace {

constexpr double kDpi = 72.0;  // the cairo devices' own resolution: 1 px = 1 pt

std::mutex plplot_mutex;

// A PNG's working memory, kept from plot to plot (under plplot_mutex): freshly allocated, these
// megabytes went back to the system after every plot and came back as page faults in the next.
struct PngMemory {
  std::vector<unsigned char> canvas;  // the cairo surface's pixels
  std::vector<unsigned char> raw;     // filtered rows, deflate's input
  std::string deflated;
};
PngMemory& pngMemory() {
  static PngMemory memory;
  return memory;
}

[[noreturn]] void fail(const std::string& path, const std::string& why) {
  throw std::runtime_error("writePlot " + path + ": " + why);
}

// PLplot's fatal errors would call exit(); turn them into exceptions instead.
int throwOnPlplotExit(const char* message) { throw std::runtime_error(std::string("PLplot: ") + message); }

std::string deviceFor(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".png") return "pngcairo";
  if (ext == ".svg") return "svg";
  if (ext == ".pdf") return "pdfcairo";
  fail(path, "unsupported extension \"" + ext + "\" (use .png, .svg or .pdf)");
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

// A PNG of a cairo RGB24 image (each pixel a native-endian 32-bit word 0xXXRRGGBB, rows `stride`
// bytes apart; the plots are opaque, so 8-bit RGB), deflated at zlib's fastest level with each row
// filtered against the one above: about a fifth of the CPU time of pngcairo's own writer (zlib
// level 6 and libpng's per-row filter search), which was a third of a graded submission's time; the
// same picture, the same bytes every run.
// The caller holds plplot_mutex (the working memory is shared).
std::string encodePng(const unsigned char* pixels, int stride, int width, int height) {
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "a pixel's bytes are read as B, G, R, X");
  const std::size_t w = std::size_t(width), row = 1 + 3 * w;
  std::vector<unsigned char>& raw = pngMemory().raw;
  raw.resize(std::size_t(height) * row);
  for (std::size_t y = 0; y < std::size_t(height); ++y) {
    const unsigned char* src = pixels + y * std::size_t(stride);
    unsigned char* out = raw.data() + y * row;
    *out++ = 2;  // filter "Up": each byte minus the one above it (the first row: minus 0)
    if (y == 0) {
      for (std::size_t x = 0; x < w; ++x, out += 3) out[0] = src[4 * x + 2], out[1] = src[4 * x + 1], out[2] = src[4 * x];
      continue;
    }
    const unsigned char* up = src - stride;
    for (std::size_t x = 0; x < w; ++x, out += 3) {
      out[0] = (unsigned char)(src[4 * x + 2] - up[4 * x + 2]);
      out[1] = (unsigned char)(src[4 * x + 1] - up[4 * x + 1]);
      out[2] = (unsigned char)(src[4 * x] - up[4 * x]);
    }
  }
  std::string& z = pngMemory().deflated;
  uLongf size = compressBound(uLong(raw.size()));
  z.resize(size);
  if (compress2(reinterpret_cast<Bytef*>(z.data()), &size, raw.data(), uLong(raw.size()), 1) != Z_OK)
    throw std::runtime_error("PNG encoding failed");
  const std::string_view idat(z.data(), size);
  std::string png = "\x89PNG\r\n\x1a\n";
  png.reserve(png.size() + 3 * 12 + 13 + idat.size());
  const auto chunk = [&](const char* type, std::string_view data) {
    const auto be32 = [&](std::uint32_t v) {
      for (int shift = 24; shift >= 0; shift -= 8) png.push_back(char((v >> shift) & 0xff));
    };
    be32(std::uint32_t(data.size()));
    const std::size_t body = png.size();
    png.append(type, 4).append(data);
    be32(std::uint32_t(crc32(0, reinterpret_cast<const Bytef*>(png.data() + body), uInt(png.size() - body))));
  };
  std::string ihdr;
  for (std::uint32_t v : {std::uint32_t(width), std::uint32_t(height)})
    for (int shift = 24; shift >= 0; shift -= 8) ihdr.push_back(char((v >> shift) & 0xff));
  ihdr += std::string("\x08\x02\x00\x00\x00", 5);  // 8-bit RGB, deflate, adaptive filters, no interlace
  chunk("IHDR", ihdr);
  chunk("IDAT", idat);
  chunk("IEND", "");
  return png;
}

// The current (fresh) stream's device, page of w × h pixels and colours, before plinit (the caller
// holds plplot_mutex).
void openStream(const std::string& device, int w, int h) {
  plsdev(device.c_str());
  plspage(kDpi, kDpi, w, h, 0, 0);
  plsfam(0, 0, 0);
  plot_detail::setColours();
}

// A picture drawn by PLplot's extcairo device on our own cairo image surface (RGB24, on the paper
// colour), read in place by the PNG encoder. It is memcairo's surface without memcairo's two copies
// of every pixel (from the caller's buffer into cairo's format and back), about 5 % of a plot's CPU:
// the same format, size, transform, antialiasing and fill rule, so the same pixels.
// The caller holds plplot_mutex (the pixels are the shared working memory's).
class Canvas {
 public:
  Canvas(int w, int h) : stride_(cairo_format_stride_for_width(CAIRO_FORMAT_RGB24, w)), pixels_(pngMemory().canvas) {
    pixels_.assign(std::size_t(stride_) * std::size_t(h), 0xff);
    surface_ = cairo_image_surface_create_for_data(pixels_.data(), CAIRO_FORMAT_RGB24, w, h, stride_);
    cr_ = cairo_create(surface_);
    if (cairo_status(cr_) != CAIRO_STATUS_SUCCESS) {  // cairo's error objects: destroying them is allowed
      cairo_destroy(cr_);
      cairo_surface_destroy(surface_);
      throw std::runtime_error("cannot make a cairo surface");
    }
  }
  ~Canvas() {
    cairo_destroy(cr_);
    cairo_surface_destroy(surface_);
  }
  Canvas(const Canvas&) = delete;
  Canvas& operator=(const Canvas&) = delete;
  cairo_t* context() const { return cr_; }
  // The pixels once drawing is done (cairo flushed).
  const unsigned char* pixels() {
    cairo_surface_flush(surface_);
    return pixels_.data();
  }
  int stride() const { return stride_; }

 private:
  int stride_;
  std::vector<unsigned char>& pixels_;
  cairo_surface_t* surface_ = nullptr;
  cairo_t* cr_ = nullptr;
};

// Draws `prepared` on `canvas` (w × h) through a fresh stream, ended on return. The caller holds
// plplot_mutex.
PlotLayout drawOnCanvas(const plot_detail::Prepared& prepared, Canvas& canvas, int w, int h) {
  plsexit(throwOnPlplotExit);
  Stream stream;
  openStream("extcairo", w, h);
  plinit();
  pl_cmd(PLESC_DEVINIT, canvas.context());
  return plot_detail::draw(prepared, w, h);
}

// An SVG or PDF: PLplot writes to a scratch file (it would exit() if it could not open one: check
// first), which is read back whole and removed.
std::string drawToScratch(const std::string& path, const plot_detail::Prepared& prepared, const std::string& device,
                          int w, int h, PlotLayout& layout) {
  const std::string scratch = path + ".plplot";
  if (std::FILE* f = std::fopen(scratch.c_str(), "wb")) {
    std::fclose(f);
  } else {
    fail(path, std::string("cannot write ") + scratch + ": " + std::strerror(errno));
  }
  {
    std::lock_guard<std::mutex> lock(plplot_mutex);
    try {
      plsexit(throwOnPlplotExit);
      Stream stream;
      openStream(device, w, h);
      plsfnam(scratch.c_str());
      plinit();
      layout = plot_detail::draw(prepared, w, h);
    } catch (const std::exception& e) {
      std::remove(scratch.c_str());
      fail(path, e.what());
    }
  }
  std::ifstream in(scratch, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const bool read_ok = !in.bad();
  in.close();
  std::remove(scratch.c_str());
  if (!read_ok) fail(path, "cannot read back " + scratch);
  return text;
}

}  // namespace

PlotWindow equalAspect(const PlotWindow& w, double frame_width, double frame_height) {
  PlotWindow out = w;
  const double per_x = (w.x1 - w.x0) / frame_width, per_y = (w.y1 - w.y0) / frame_height;  // data per length
  if (per_x < per_y) {  // x is stretched: show more of it
    const double half = 0.5 * per_y * frame_width, mid = 0.5 * (w.x0 + w.x1);
    out.x0 = mid - half, out.x1 = mid + half;
  } else if (per_y < per_x) {
    const double half = 0.5 * per_x * frame_height, mid = 0.5 * (w.y0 + w.y1);
    out.y0 = mid - half, out.y1 = mid + half;
  }
  return out;
}

PlotLayout writePlot(const std::string& path, const PlotSpec& spec, int width_px, int height_px) {
  const std::string device = deviceFor(path);
  validate(path, spec);
  if (width_px < 100 || height_px < 100 || width_px > 10000 || height_px > 10000)
    fail(path, "size " + std::to_string(width_px) + "x" + std::to_string(height_px) + " is out of range");
  const plot_detail::Prepared prepared = plot_detail::prepare(path, spec);
  PlotLayout layout;
  std::string text;

  if (device == "pngcairo") {
    // A PNG is drawn in memory and encoded here (pngcairo's writer is slow): no scratch file, the
    // bytes go straight to the checked writer.
    std::lock_guard<std::mutex> lock(plplot_mutex);
    try {
      Canvas canvas(width_px, height_px);
      layout = drawOnCanvas(prepared, canvas, width_px, height_px);
      text = encodePng(canvas.pixels(), canvas.stride(), width_px, height_px);
    } catch (const std::exception& e) {
      fail(path, e.what());
    }
  } else {
    text = drawToScratch(path, prepared, device, width_px, height_px, layout);
  }

  // Fix up, check it is whole, and publish it through the checked writer.
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
  return layout;
}

void warmUpPlotting() {
  // A full-size plot with every printable ASCII glyph in each of its fonts (title, labels, ticks,
  // legend), drawn in memory: a forked grader inherits the loaded fonts and the glyphs' caches.
  std::string glyphs;
  for (char c = ' '; c <= '~'; ++c) glyphs += c;
  PlotSpec spec;
  spec.title = spec.xlabel = spec.ylabel = glyphs;
  PlotSeries smooth{glyphs, {0, 1, 2, 3}, {0, 1, 0, 1}}, noisy{"noise", {}, {}};
  for (int i = 0; i <= 400; ++i) noisy.x.push_back(i * 0.01), noisy.y.push_back(i % 2 ? 1.0 : -1.0);
  spec.series = {noisy, smooth};
  spec.bands = {{"band", {0, 4}, {-0.1, -0.1}, {0.1, 0.1}}};
  spec.spans = {{"span", 0, 0.5}};
  const int w = 640, h = 360;
  std::lock_guard<std::mutex> lock(plplot_mutex);
  try {
    Canvas canvas(w, h);
    drawOnCanvas(plot_detail::prepare("warm-up", spec), canvas, w, h);
  } catch (const std::exception&) {
    // Nothing lost: the first plot loads it all instead.
  }
}

}  // namespace dyn
