// Turning traces into pictures: PNG frames and an MP4 of a run, the Bullet run as a ghost, and
// single frames at chosen times (dynlab figure's stills).
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

// The trace row nearest simulated time t (rows are dt apart from t = 0; clamped to the last row).
std::size_t rowAt(const Trace& trace, double dt, double t);
// Trace rows shown at `fps` frames per second of simulated time.
std::vector<std::size_t> frameRows(const Trace& trace, double dt, int fps);

// The frame at one trace row: the lab's scene, and its overlay panel unless overlay is false
// (title, when not empty, replaces the panel's title).
Image renderRow(Renderer& renderer, const Lab& lab, const Trace& trace, std::size_t row, const Trace* ghost,
                bool overlay = true, const std::string& title = "");

// The scene and, when overlay is not null, the panel at one trace row: what renderFrames draws.
using DrawRow = std::function<void(std::size_t row, Scene& scene, Overlay* overlay)>;

// Renders the trace's rows at options.fps frames per second of simulated time (steps of dt); writes
// video.mp4 and/or frames/NNNNN.png (PngEncoding::Fast) into dir, with a progress bar on a terminal
// (app/shared/progress.h). Returns the frame count.
int renderFrames(const DrawRow& draw, const Trace& trace, double dt, const MovieOptions& options,
                 const std::filesystem::path& dir);

// Renders the run; writes video.mp4 and/or frames/NNNNN.png (PngEncoding::Fast) into dir, with a
// progress bar on a terminal (app/shared/progress.h). Returns the frame count.
int renderRun(const Lab& lab, const Trace& trace, const Trace* ghost, const MovieOptions& options,
              const std::filesystem::path& dir);

}  // namespace dyn::app
