// dynlab.Lab.frame and .video: the last run drawn as the CLI draws it (app/movie: the lab's scene and
// overlay panel, the other engine's run as a ghost), offscreen through OSMesa, without the GIL.
#include <cstring>
#include <filesystem>
#include <mutex>
#include <system_error>

#include "app/shared/movie.h"
#include "app/python/lab_object.h"
#include "grading/scenario.h"
#include "labs/numbers.h"
#include "render/gl_context.h"

namespace dyn::python {

namespace fs = std::filesystem;

std::shared_ptr<const LabObject::LastRun> LabObject::lastRun() const {
  if (!last_) throw InputError(kArgument, "run", "expected a run first: lab.run() and then frame() or video()");
  return last_;
}

std::pair<const Trace*, const Trace*> LabObject::shown(const LastRun& r, const std::string& engine) {
  if (engine != "hand" && engine != "bullet")
    throw InputError(kArgument, "engine", "expected \"hand\" or \"bullet\", got \"" + engine + "\"");
  const auto& main = engine == "hand" ? r.hand : r.bullet;
  const auto& other = engine == "hand" ? r.bullet : r.hand;
  if (!main) throw InputError(kArgument, "engine", "expected an engine the last run ran; it did not run " + engine);
  return {&*main, other ? &*other : nullptr};
}

namespace {

// Drawing is one at a time in the process: the overlay's Dear ImGui context is made current
// globally. Taken with the GIL released (a thread waiting for it lets Python run).
std::mutex& drawing() {
  static std::mutex m;
  return m;
}

// The frame sizes the CLI accepts (render/image.h parseFrameSize: up to 8192 a side).
void checkSize(int width, int height) {
  if (width < 64 || height < 48 || width > 8192 || height > 8192)
    throw InputError(kArgument, "width, height", "expected a frame from 64x48 to 8192x8192 pixels, got " +
                                                     std::to_string(width) + "x" + std::to_string(height));
}

}  // namespace

py::array LabObject::frame(double t, const std::string& engine, int width, int height, bool overlay) const {
  checkSize(width, height);
  // This call's own reference to the last run: a run() in another thread meanwhile replaces last_, not it.
  const std::shared_ptr<const LastRun> run = lastRun();
  const auto [trace, ghost] = shown(*run, engine);
  const Lab& lab = *run->lab;
  if (!(t >= 0) || t > lab.duration() + lab.dt())
    throw InputError(kArgument, "t", "expected a time in [0, " + fmtNumber(lab.duration()) + "] s, got " + exactNumber(t));
  Image image;
  {
    py::gil_scoped_release release;
    const std::lock_guard<std::mutex> one_at_a_time(drawing());
    auto context = makeOffscreenContext(width, height);
    Renderer renderer(*context);
    image = app::renderRow(renderer, lab, *trace, app::rowAt(*trace, lab.dt(), t), ghost, overlay);
  }
  // RGBA rows top-down → an (height, width, 3) RGB array.
  py::array_t<std::uint8_t> out({height, width, 3});
  auto px = out.mutable_unchecked<3>();
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c) px(y, x, c) = image.pixel(x, y)[c];
  return out;
}

std::string LabObject::video(const std::string& path, const std::string& engine, int width, int height) const {
  checkSize(width, height);
  if ((width | height) & 1) throw InputError(kArgument, "width, height", "expected even sides (H.264 4:2:0)");
  const std::shared_ptr<const LastRun> run = lastRun();  // as in frame(): this call's own
  const auto [trace, ghost] = shown(*run, engine);
  const Lab& lab = *run->lab;
  const fs::path target = fs::absolute(path);
  if (target.filename().empty() || fs::is_directory(target))
    throw InputError(path, "", "expected a file name for the video (e.g. run.mp4), not a folder");
  if (!fs::is_directory(target.parent_path()))
    throw InputError(path, "", "expected a path in an existing folder");
  // Drawn into a scratch folder beside the target, then renamed over it: whole or not at all.
  fs::path scratch;
  for (int i = 0;; ++i) {
    scratch = target.parent_path() / (".dynlab-video-" + std::to_string(i));
    std::error_code ec;
    if (fs::create_directory(scratch, ec)) break;
    if (ec || i > 1000) throw std::runtime_error(path + ": cannot create a scratch folder beside it: " + ec.message());
  }
  try {
    py::gil_scoped_release release;
    const std::lock_guard<std::mutex> one_at_a_time(drawing());
    app::renderRun(lab, *trace, ghost, {width, height, 30, true, false}, scratch);
    fs::rename(scratch / "video.mp4", target);
  } catch (...) {
    std::error_code ec;
    fs::remove_all(scratch, ec);
    throw;
  }
  std::error_code ec;
  fs::remove_all(scratch, ec);
  return target.string();
}

}  // namespace dyn::python
