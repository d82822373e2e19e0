#include "tests/support/movie_file.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/pixdesc.h>
#include <libswscale/swscale.h>
}

#include <cmath>
#include <cstring>
#include <limits>

namespace lantern::testing {
namespace {

// Owns the decoding state; frees it however read_movie returns.
struct Decoder {
  AVFormatContext *format = nullptr;
  AVCodecContext *codec = nullptr;
  AVFrame *frame = nullptr;
  AVPacket *packet = nullptr;
  SwsContext *scale = nullptr;
  ~Decoder() {
    sws_freeContext(scale);
    av_packet_free(&packet);
    av_frame_free(&frame);
    avcodec_free_context(&codec);
    avformat_close_input(&format);
  }
};

// Appends the frames the decoder has ready.
bool take_frames(Decoder &d, const AVStream *stream, MovieFrames *out) {
  for (;;) {
    const int got = avcodec_receive_frame(d.codec, d.frame);
    if (got == AVERROR(EAGAIN) || got == AVERROR_EOF) return true;
    if (got < 0) {
      out->error = "decoding failed";
      return false;
    }
    const AVPixelFormat format = AVPixelFormat(d.frame->format);
    out->width = d.frame->width;
    out->height = d.frame->height;
    out->pixel_format = av_get_pix_fmt_name(format);
    d.scale = sws_getCachedContext(d.scale, d.frame->width, d.frame->height, format, d.frame->width,
                                   d.frame->height, AV_PIX_FMT_RGB24,
                                   SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT, nullptr,
                                   nullptr, nullptr);
    const bool yuv = !(av_pix_fmt_desc_get(format)->flags & AV_PIX_FMT_FLAG_RGB);
    if (yuv)
      sws_setColorspaceDetails(d.scale, sws_getCoefficients(SWS_CS_ITU709), 0,
                               sws_getCoefficients(SWS_CS_ITU709), 1, 0, 1 << 16, 1 << 16);
    std::vector<uint8_t> rgb(size_t(d.frame->width) * d.frame->height * 3);
    uint8_t *planes[1] = {rgb.data()};
    const int strides[1] = {d.frame->width * 3};
    sws_scale(d.scale, d.frame->data, d.frame->linesize, 0, d.frame->height, planes, strides);
    out->rgb.push_back(std::move(rgb));
    const int64_t pts = d.frame->best_effort_timestamp;
    out->index.push_back(av_rescale_q(
        pts, stream->time_base,
        av_inv_q(stream->avg_frame_rate.num ? stream->avg_frame_rate : stream->r_frame_rate)));
    av_frame_unref(d.frame);
  }
}

}  // namespace

MovieFrames read_movie(const std::string &path) {
  MovieFrames out;
  Decoder d;
  if (avformat_open_input(&d.format, path.c_str(), nullptr, nullptr) < 0) {
    out.error = "cannot open " + path;
    return out;
  }
  if (avformat_find_stream_info(d.format, nullptr) < 0) {
    out.error = "no stream information in " + path;
    return out;
  }
  const int s = av_find_best_stream(d.format, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
  if (s < 0) {
    out.error = "no video stream in " + path;
    return out;
  }
  const AVStream *stream = d.format->streams[s];
  const AVCodec *codec = avcodec_find_decoder(stream->codecpar->codec_id);
  d.codec = avcodec_alloc_context3(codec);
  d.frame = av_frame_alloc();
  d.packet = av_packet_alloc();
  if (!codec || !d.codec || avcodec_parameters_to_context(d.codec, stream->codecpar) < 0 ||
      avcodec_open2(d.codec, codec, nullptr) < 0) {
    out.error = "no decoder for " + path;
    return out;
  }
  out.codec = avcodec_get_name(stream->codecpar->codec_id);
  while (av_read_frame(d.format, d.packet) >= 0) {
    const bool ours = d.packet->stream_index == s;
    const int sent = ours ? avcodec_send_packet(d.codec, d.packet) : 0;
    av_packet_unref(d.packet);
    if (sent < 0) {
      out.error = "a packet of " + path + " does not decode";
      return out;
    }
    if (ours && !take_frames(d, stream, &out)) return out;
  }
  avcodec_send_packet(d.codec, nullptr);
  take_frames(d, stream, &out);
  return out;
}

double movie_psnr(const std::vector<uint8_t> &movie, int movie_width, const uint8_t *image,
                  int width, int height, int channels) {
  double squared = 0.0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c) {
        const double e = double(movie[(size_t(y) * movie_width + x) * 3 + c]) -
                         double(image[(size_t(y) * width + x) * channels + c]);
        squared += e * e;
      }
  if (squared == 0.0) return std::numeric_limits<double>::infinity();
  const double mse = squared / (double(width) * height * 3);
  return 10.0 * std::log10(255.0 * 255.0 / mse);
}

}  // namespace lantern::testing
