// VideoWriter: RGBA frames -> yuv420p (libswscale, BT.709 limited range) -> H.264 (libx264,
// single-threaded for reproducible bytes) -> MP4 with +faststart, via libavformat in-process.
// Written under "<path>.tmp" and renamed on close(); abandoned writers delete the temporary.
#include "render/video.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace dyn {
namespace {

std::string avError(int code) {
  char buf[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, buf, sizeof buf);
  return buf;
}

}  // namespace

struct VideoWriter::Impl {
  std::string path, temp;
  int width, height, fps;
  int frames = 0;
  bool finished = false;  // closed (renamed) successfully
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  AVStream* stream = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  SwsContext* sws = nullptr;

  [[noreturn]] void fail(const std::string& what, int code = 0) const {
    std::string msg = "video '" + path + "': " + what;
    if (code < 0) msg += ": " + avError(code);
    throw std::runtime_error(msg);
  }

  void open() {
    // libav* log every encode at INFO; keep a CLI quiet unless someone chose a level.
    if (av_log_get_level() == AV_LOG_INFO) av_log_set_level(AV_LOG_WARNING);
    if (width <= 0 || height <= 0 || width % 2 || height % 2)
      fail("width and height must be positive and even, got " + std::to_string(width) + "x" +
           std::to_string(height));
    if (fps <= 0) fail("fps must be positive");
    int rc = avformat_alloc_output_context2(&format, nullptr, "mp4", temp.c_str());
    if (rc < 0 || !format) fail("cannot create MP4 muxer", rc);
    // Reproducible container: no creation time or muxer version strings.
    format->flags |= AVFMT_FLAG_BITEXACT;

    // H.264: libx264 if present, otherwise whatever H.264 encoder libavcodec has.
    const AVCodec* encoder = avcodec_find_encoder_by_name("libx264");
    if (!encoder) encoder = avcodec_find_encoder(AV_CODEC_ID_H264);
    if (!encoder) fail("no H.264 encoder in libavcodec");
    stream = avformat_new_stream(format, nullptr);
    codec = avcodec_alloc_context3(encoder);
    if (!stream || !codec) fail("out of memory");
    codec->width = width;
    codec->height = height;
    codec->time_base = AVRational{1, fps};
    codec->framerate = AVRational{fps, 1};
    codec->pix_fmt = AV_PIX_FMT_YUV420P;
    codec->gop_size = 2 * fps;
    codec->thread_count = 1;  // multithreaded x264 output depends on timing
    codec->color_range = AVCOL_RANGE_MPEG;
    codec->colorspace = AVCOL_SPC_BT709;
    codec->color_primaries = AVCOL_PRI_BT709;
    codec->color_trc = AVCOL_TRC_BT709;
    if (format->oformat->flags & AVFMT_GLOBALHEADER) codec->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    AVDictionary* codec_opts = nullptr;
    if (std::string(encoder->name) == "libx264") {
      av_dict_set(&codec_opts, "preset", "veryfast", 0);
      av_dict_set(&codec_opts, "crf", "23", 0);
    }
    rc = avcodec_open2(codec, encoder, &codec_opts);
    av_dict_free(&codec_opts);
    if (rc < 0) fail(std::string("cannot open encoder ") + encoder->name, rc);
    rc = avcodec_parameters_from_context(stream->codecpar, codec);
    if (rc < 0) fail("cannot copy codec parameters", rc);
    stream->time_base = codec->time_base;
    stream->avg_frame_rate = codec->framerate;

    rc = avio_open(&format->pb, temp.c_str(), AVIO_FLAG_WRITE);
    if (rc < 0) fail("cannot open " + temp + " for writing", rc);
    // moov atom first, so browsers can start playing before the whole file has arrived.
    AVDictionary* mux_opts = nullptr;
    av_dict_set(&mux_opts, "movflags", "+faststart", 0);
    rc = avformat_write_header(format, &mux_opts);
    av_dict_free(&mux_opts);
    if (rc < 0) fail("cannot write MP4 header", rc);

    // Reused frame and the RGBA -> YUV converter (BT.709 matrix, limited range, like the tags).
    frame = av_frame_alloc();
    packet = av_packet_alloc();
    if (!frame || !packet) fail("out of memory");
    frame->format = AV_PIX_FMT_YUV420P;
    frame->width = width;
    frame->height = height;
    rc = av_frame_get_buffer(frame, 0);
    if (rc < 0) fail("cannot allocate frame", rc);
    sws = sws_getContext(width, height, AV_PIX_FMT_RGBA, width, height, AV_PIX_FMT_YUV420P,
                         SWS_BILINEAR | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INP, nullptr, nullptr,
                         nullptr);
    if (!sws) fail("cannot create RGBA->YUV converter");
    sws_setColorspaceDetails(sws, sws_getCoefficients(SWS_CS_ITU709), 1,
                             sws_getCoefficients(SWS_CS_ITU709), 0, 0, 1 << 16, 1 << 16);
  }

  // Sends a frame (or nullptr to flush) and writes every packet the encoder returns.
  void encode(AVFrame* input) {
    int rc = avcodec_send_frame(codec, input);
    if (rc < 0) fail("encoding failed", rc);
    while (true) {
      rc = avcodec_receive_packet(codec, packet);
      if (rc == AVERROR(EAGAIN) || rc == AVERROR_EOF) return;
      if (rc < 0) fail("encoding failed", rc);
      // Every packet lasts one frame: otherwise the muxer gives the last one no duration.
      packet->duration = 1;
      av_packet_rescale_ts(packet, codec->time_base, stream->time_base);
      packet->stream_index = stream->index;
      rc = av_interleaved_write_frame(format, packet);  // takes the packet's reference
      if (rc < 0) fail("cannot write packet", rc);
    }
  }

  void addFrame(const Image& image) {
    if (finished || !codec) fail("addFrame after close()");
    if (image.width != width || image.height != height ||
        image.rgba.size() != std::size_t(width) * height * 4)
      fail("frame is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
           ", expected " + std::to_string(width) + "x" + std::to_string(height));
    int rc = av_frame_make_writable(frame);
    if (rc < 0) fail("frame not writable", rc);
    const uint8_t* src[1] = {image.rgba.data()};
    const int src_stride[1] = {width * 4};
    sws_scale(sws, src, src_stride, 0, height, frame->data, frame->linesize);
    frame->pts = frames++;
    encode(frame);
  }

  void close() {
    if (finished) return;
    encode(nullptr);
    int rc = av_write_trailer(format);  // with faststart, rewrites the file with moov first
    if (rc < 0) fail("cannot finalise MP4", rc);
    rc = avio_closep(&format->pb);
    if (rc < 0) fail("cannot close " + temp, rc);
    std::error_code ec;
    std::filesystem::rename(temp, path, ec);
    if (ec) fail("cannot rename " + temp + ": " + ec.message());
    finished = true;
  }

  // Frees everything; removes the temporary unless close() succeeded.
  void release() {
    sws_freeContext(sws);
    sws = nullptr;
    av_frame_free(&frame);
    av_packet_free(&packet);
    avcodec_free_context(&codec);
    if (format) {
      if (format->pb) avio_closep(&format->pb);
      avformat_free_context(format);
      format = nullptr;
    }
    if (!finished) {
      std::error_code ec;
      std::filesystem::remove(temp, ec);
    }
  }
};

VideoWriter::VideoWriter(const std::string& path, int width, int height, int fps)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->temp = path + ".tmp";
  impl_->width = width;
  impl_->height = height;
  impl_->fps = fps;
  try {
    impl_->open();
  } catch (...) {
    impl_->release();
    throw;
  }
}

VideoWriter::~VideoWriter() { impl_->release(); }

void VideoWriter::addFrame(const Image& frame) { impl_->addFrame(frame); }

void VideoWriter::close() { impl_->close(); }

int VideoWriter::frameCount() const { return impl_->frames; }

}  // namespace dyn
