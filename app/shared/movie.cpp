// Rendering runs to PNG frames and H.264 video (render/), offscreen through OSMesa.
#include "app/shared/movie.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "app/shared/progress.h"
#include "render/video.h"

namespace dyn::app {

std::size_t rowAt(const Trace& trace, double dt, double t) {
  const long long r = std::llround(t / dt);
  if (trace.rows() == 0 || r <= 0) return 0;
  return std::min(std::size_t(r), trace.rows() - 1);
}

std::vector<std::size_t> frameRows(const Trace& trace, double dt, int fps) {
  std::vector<std::size_t> rows;
  const double period = 1.0 / fps;
  for (int k = 0;; ++k) {
    const auto r = std::size_t(std::llround(k * period / dt));
    if (r >= trace.rows()) break;
    rows.push_back(r);
  }
  return rows;
}

Image renderRow(Renderer& renderer, const Lab& lab, const Trace& trace, std::size_t row, const Trace* ghost,
                bool overlay, const std::string& title) {
  Scene scene;
  Overlay panel;
  lab.scene(trace, row, ghost, scene);
  if (overlay) lab.overlay(trace, row, panel);
  if (!title.empty()) panel.title = title;
  return renderer.render(scene, overlay ? &panel : nullptr);
}

int renderFrames(const DrawRow& draw, const Trace& trace, double dt, const MovieOptions& o,
                 const std::filesystem::path& dir) {
  // Never more frames than a run may draw (labs/settings.h): the commands refuse before they run, Python here.
  if (const std::string problem = frameBoundProblem(double(trace.rows() ? trace.rows() - 1 : 0) * dt, o.fps); !problem.empty())
    throw InputError("<frames>", o.video ? "video" : "frames", problem);
  auto context = makeOffscreenContext(o.width, o.height);
  Renderer renderer(*context);
  std::unique_ptr<VideoWriter> video;
  if (o.video) video = std::make_unique<VideoWriter>((dir / "video.mp4").string(), o.width, o.height, o.fps);
  if (o.frames) std::filesystem::create_directories(dir / "frames");
  int n = 0;
  const std::vector<std::size_t> rows = frameRows(trace, dt, o.fps);
  // A bar on a terminal (nothing otherwise): a 20 s run is 600 frames.
  Progress progress(o.video && o.frames ? "video and frames" : o.video ? "video" : "frames", rows.size());
  for (std::size_t row : rows) {
    Scene scene;
    Overlay panel;
    draw(row, scene, &panel);
    const Image image = renderer.render(scene, &panel);
    if (video) video->addFrame(image);
    if (o.frames) {
      char name[32];
      std::snprintf(name, sizeof name, "%05d.png", n);
      if (std::string why; !writePng((dir / "frames" / name).string(), image, &why, PngEncoding::Fast))
        throw std::runtime_error(why);
    }
    progress.set(std::size_t(++n));
  }
  if (video) video->close();
  return n;
}

int renderRun(const Lab& lab, const Trace& trace, const Trace* ghost, const MovieOptions& o,
              const std::filesystem::path& dir) {
  const DrawRow draw = [&](std::size_t row, Scene& scene, Overlay* panel) {
    lab.scene(trace, row, ghost, scene);
    if (panel) lab.overlay(trace, row, *panel);
  };
  return renderFrames(draw, trace, lab.dt(), o, dir);
}

}  // namespace dyn::app
