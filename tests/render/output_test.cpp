// Output tests: PNG round trip through stb_image, and H.264 MP4 files that decode to exactly
// the frames written; abandoned video writers leave nothing behind.
#include <doctest/doctest.h>
#include <stb_image.h>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/pixdesc.h>
}

#include <chrono>
#include <filesystem>
#include <stdexcept>

#include "render/video.h"
#include "tests/render/test_scene.h"

using namespace dyn;
namespace fs = std::filesystem;

namespace {

// A deterministic gradient with a moving square, so the encoder has something to do.
Image syntheticFrame(int width, int height, int t) {
  Image image;
  image.width = width;
  image.height = height;
  image.rgba.resize(std::size_t(width) * height * 4);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      std::uint8_t* p = &image.rgba[(std::size_t(y) * width + x) * 4];
      const bool square = x >= 10 + 8 * t && x < 70 + 8 * t && y >= 100 && y < 160;
      p[0] = square ? 220 : std::uint8_t(x * 255 / width);
      p[1] = square ? 40 : std::uint8_t(y * 255 / height);
      p[2] = square ? 40 : 128;
      p[3] = 255;
    }
  return image;
}

struct Probe {
  int frames = 0;
  std::string codec, pix_fmt;
  int width = 0, height = 0;
};

// Decodes every frame of the first video stream.
Probe probe(const std::string& path) {
  Probe result;
  AVFormatContext* format = nullptr;
  REQUIRE(avformat_open_input(&format, path.c_str(), nullptr, nullptr) == 0);
  REQUIRE(avformat_find_stream_info(format, nullptr) >= 0);
  const int index = av_find_best_stream(format, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
  REQUIRE(index >= 0);
  const AVCodecParameters* par = format->streams[index]->codecpar;
  result.codec = avcodec_get_name(par->codec_id);
  const char* pix = av_get_pix_fmt_name(AVPixelFormat(par->format));
  result.pix_fmt = pix ? pix : "?";
  result.width = par->width;
  result.height = par->height;
  const AVCodec* decoder = avcodec_find_decoder(par->codec_id);
  REQUIRE(decoder);
  AVCodecContext* codec = avcodec_alloc_context3(decoder);
  avcodec_parameters_to_context(codec, par);
  REQUIRE(avcodec_open2(codec, decoder, nullptr) == 0);
  AVPacket* packet = av_packet_alloc();
  AVFrame* frame = av_frame_alloc();
  auto drain = [&] {
    while (avcodec_receive_frame(codec, frame) == 0) ++result.frames;
  };
  while (av_read_frame(format, packet) >= 0) {
    if (packet->stream_index == index && avcodec_send_packet(codec, packet) == 0) drain();
    av_packet_unref(packet);
  }
  avcodec_send_packet(codec, nullptr);
  drain();
  av_frame_free(&frame);
  av_packet_free(&packet);
  avcodec_free_context(&codec);
  avformat_close_input(&format);
  return result;
}

std::string readAll(const std::string& path) {
  std::string bytes(fs::file_size(path), '\0');
  FILE* f = std::fopen(path.c_str(), "rb");
  REQUIRE(f);
  CHECK(std::fread(bytes.data(), 1, bytes.size(), f) == bytes.size());
  std::fclose(f);
  return bytes;
}

}  // namespace

TEST_CASE("a rendered frame survives a PNG round trip") {
  auto context = makeOffscreenContext(160, 120);
  Renderer renderer(*context);
  const Image image = renderer.render(test::redCapsuleScene(), nullptr);
  const std::string path = test::tempPath("roundtrip.png");
  REQUIRE(writePng(path, image));
  CHECK_FALSE(fs::exists(path + ".tmp"));
  int w = 0, h = 0, n = 0;
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &n, 4);
  REQUIRE(data);
  CHECK(w == 160);
  CHECK(h == 120);
  CHECK(std::equal(image.rgba.begin(), image.rgba.end(), data));
  stbi_image_free(data);
  fs::remove(path);
}

TEST_CASE("fast PNG frames: the same pixels, the same bytes every time, faster, and stills unchanged") {
  auto context = makeOffscreenContext(640, 480);
  Renderer renderer(*context);
  const Overlay overlay = test::sampleOverlay();
  const Image image = renderer.render(test::redCapsuleScene(), &overlay);
  const std::string small = test::tempPath("small.png"), fast = test::tempPath("fast.png"), again = test::tempPath("again.png");
  auto timed = [&](const std::string& path, PngEncoding e) {
    const auto t0 = std::chrono::steady_clock::now();
    REQUIRE(writePng(path, image, nullptr, e));
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  const std::string before = (timed(small, PngEncoding::Small), readAll(small));
  double t_small = 1e9, t_fast = 1e9;
  for (int i = 0; i < 3; ++i) t_small = std::min(t_small, timed(small, PngEncoding::Small)), t_fast = std::min(t_fast, timed(fast, PngEncoding::Fast));
  MESSAGE("640x480 frame: small ", t_small * 1e3, " ms, ", fs::file_size(small), " bytes; fast ", t_fast * 1e3, " ms, ",
          fs::file_size(fast), " bytes");
  // Decodes to exactly the frame.
  int w = 0, h = 0, n = 0;
  unsigned char* data = stbi_load(fast.c_str(), &w, &h, &n, 4);
  REQUIRE(data);
  CHECK(w == 640);
  CHECK(std::equal(image.rgba.begin(), image.rgba.end(), data));
  stbi_image_free(data);
  // Deterministic, not the default encoding, and the default is left as it was (stb's settings are global).
  REQUIRE(writePng(again, image, nullptr, PngEncoding::Fast));
  CHECK(readAll(again) == readAll(fast));
  CHECK(readAll(fast) != before);
  CHECK(readAll(small) == before);
  CHECK(t_fast < t_small);
  CHECK(fs::file_size(fast) < 2 * fs::file_size(small));
  for (const auto& p : {small, fast, again}) fs::remove(p);
}

TEST_CASE("writePng fails cleanly") {
  CHECK_FALSE(writePng(test::tempPath("empty.png"), Image{}));
  Image tiny;
  tiny.width = tiny.height = 2;
  tiny.rgba.assign(16, 255);
  const std::string bad = "/nonexistent_dir_dynlab/x.png";
  CHECK_FALSE(writePng(bad, tiny));
  CHECK_FALSE(fs::exists(bad));
}

TEST_CASE("30 frames at 30 fps decode to 30 H.264 yuv420p frames") {
  const std::string path = test::tempPath("video.mp4");
  {
    VideoWriter writer(path, 640, 480, 30);
    for (int t = 0; t < 30; ++t) writer.addFrame(syntheticFrame(640, 480, t));
    CHECK(writer.frameCount() == 30);
    CHECK_FALSE(fs::exists(path));  // only the temporary until close()
    writer.close();
  }
  REQUIRE(fs::exists(path));
  CHECK_FALSE(fs::exists(path + ".tmp"));
  const Probe p = probe(path);
  CHECK(p.frames == 30);
  CHECK(p.codec == "h264");
  CHECK(p.pix_fmt == "yuv420p");
  CHECK(p.width == 640);
  CHECK(p.height == 480);

  // Same input, same bytes.
  const std::string again = test::tempPath("video2.mp4");
  {
    VideoWriter writer(again, 640, 480, 30);
    for (int t = 0; t < 30; ++t) writer.addFrame(syntheticFrame(640, 480, t));
    writer.close();
  }
  CHECK(readAll(path) == readAll(again));
  fs::remove(path);
  fs::remove(again);
}

TEST_CASE("a VideoWriter destroyed without close() leaves no file") {
  const std::string path = test::tempPath("abandoned.mp4");
  {
    VideoWriter writer(path, 320, 240, 30);
    for (int t = 0; t < 5; ++t) writer.addFrame(syntheticFrame(320, 240, t));
  }
  CHECK_FALSE(fs::exists(path));
  CHECK_FALSE(fs::exists(path + ".tmp"));
}

TEST_CASE("VideoWriter rejects bad sizes and frames") {
  CHECK_THROWS_AS(VideoWriter(test::tempPath("odd.mp4"), 641, 480, 30), std::runtime_error);
  CHECK_THROWS_AS(VideoWriter("/nonexistent_dir_dynlab/v.mp4", 64, 48, 30), std::runtime_error);
  const std::string path = test::tempPath("mismatch.mp4");
  VideoWriter writer(path, 64, 48, 30);
  CHECK_THROWS_AS(writer.addFrame(syntheticFrame(32, 24, 0)), std::runtime_error);
}

TEST_CASE("frame sizes parse only as a whole WIDTHxHEIGHT within the bounds") {
  int w = 0, h = 0;
  REQUIRE(parseFrameSize("1920x1080", 16, 16, w, h));
  CHECK(w == 1920);
  CHECK(h == 1080);
  for (const char* bad : {"", "1920", "1920x", "x1080", "1920x1080px", "1920*1080", "15x100", "100x9000", "-5x100"}) {
    CAPTURE(bad);
    CHECK_FALSE(parseFrameSize(bad, 16, 16, w, h));
  }
  CHECK_FALSE(parseFrameSize("399x300", 400, 300, w, h));
  CHECK(parseFrameSize("400x300", 400, 300, w, h));
}
