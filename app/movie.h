// Turning traces into pictures: PNG frames and an MP4 of a run, the Bullet run as a ghost.
#pragma once
#include <filesystem>
#include <functional>

#include "labs/lab.h"
#include "render/renderer.h"

namespace dyn::app {

struct MovieOptions {
  int width = 640, height = 480, fps = 30;
  bool video = false, frames = false;
};

// Trace rows shown at `fps` frames per second of simulated time.
std::vector<std::size_t> frameRows(const Trace& trace, double dt, int fps);

// Renders the run; writes video.mp4 and/or frames/NNNNN.png into dir. Returns the frame count.
int renderRun(const Lab& lab, const Trace& trace, const Trace* ghost, const MovieOptions& options,
              const std::filesystem::path& dir);

}  // namespace dyn::app
