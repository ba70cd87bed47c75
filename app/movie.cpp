// Rendering runs to PNG frames and H.264 video (render/), offscreen through OSMesa.
#include "app/movie.h"

#include <cmath>
#include <cstdio>

#include "render/video.h"

namespace dyn::app {

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

int renderRun(const Lab& lab, const Trace& trace, const Trace* ghost, const MovieOptions& o,
              const std::filesystem::path& dir) {
  auto context = makeOffscreenContext(o.width, o.height);
  Renderer renderer(*context);
  std::unique_ptr<VideoWriter> video;
  if (o.video) video = std::make_unique<VideoWriter>((dir / "video.mp4").string(), o.width, o.height, o.fps);
  if (o.frames) std::filesystem::create_directories(dir / "frames");
  int n = 0;
  for (std::size_t row : frameRows(trace, lab.dt(), o.fps)) {
    Scene scene;
    Overlay overlay;
    lab.scene(trace, row, ghost, scene);
    lab.overlay(trace, row, overlay);
    const Image image = renderer.render(scene, &overlay);
    if (video) video->addFrame(image);
    if (o.frames) {
      char name[32];
      std::snprintf(name, sizeof name, "%05d.png", n);
      if (!writePng((dir / "frames" / name).string(), image))
        throw std::runtime_error("cannot write " + (dir / "frames" / name).string());
    }
    ++n;
  }
  if (video) video->close();
  return n;
}

}  // namespace dyn::app
