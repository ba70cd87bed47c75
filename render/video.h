// VideoWriter: H.264 MP4 (yuv420p, plays in a browser) through libavcodec/libavformat,
// in-process. Writes to a temporary name and renames on close(), so a failed run leaves no
// half-written video behind.
#pragma once
#include <memory>
#include <string>

#include "render/image.h"

namespace dyn {

class VideoWriter {
 public:
  // Throws std::runtime_error naming the path on failure. width/height must be even.
  VideoWriter(const std::string& path, int width, int height, int fps);
  ~VideoWriter();  // abandons (deletes the temporary) if close() was not called
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  void addFrame(const Image& frame);  // same size as opened
  void close();                       // flushes, finalises, renames into place
  int frameCount() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dyn
