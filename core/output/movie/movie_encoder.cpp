// The FFmpeg implementation of movie_encoder.h (built with LANTERN_WITH_MOVIE).
#include "core/output/movie/movie_encoder.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <vector>

#include "core/output/atomic_file.h"

namespace lantern {
namespace {

// One encoder a codec family may use, in order of preference.
struct EncoderSpec {
  const char *family;   // the `codec:` word
  const char *encoder;  // libavcodec's encoder name
  int max_quality;      // CRF range 0..max_quality; 0 when the codec takes no quality
  int default_quality;
};

// Software encoders only: they work on every machine the library runs on (hardware encoders
// need devices and frames of their own).
constexpr EncoderSpec kEncoders[] = {{"h264", "libx264", 51, 23},   {"hevc", "libx265", 51, 28},
                                     {"vp9", "libvpx-vp9", 63, 32}, {"av1", "libaom-av1", 63, 35},
                                     {"av1", "libsvtav1", 63, 35},  {"ffv1", "ffv1", 0, 0}};

// The families `auto` tries, by container.
constexpr const char *kAutoMpeg4[] = {"h264", "hevc", "av1", "vp9"};
constexpr const char *kAutoWebm[] = {"vp9", "av1"};

std::string lower(std::string s) {
  for (char &c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string extension_of(const std::string &path) {
  return lower(std::filesystem::path(path).extension().string());
}

// libavformat's muxer for the file's extension (the loader allows these four).
const char *muxer_for(const std::string &path) {
  const std::string ext = extension_of(path);
  if (ext == ".mp4") return "mp4";
  if (ext == ".mov") return "mov";
  if (ext == ".webm") return "webm";
  return "matroska";
}

bool fragmented_mpeg4(const std::string &muxer) {
  return muxer == "mp4" || muxer == "mov";
}

const EncoderSpec *first_present(const char *family) {
  for (const EncoderSpec &spec : kEncoders)
    if (std::strcmp(spec.family, family) == 0 && avcodec_find_encoder_by_name(spec.encoder))
      return &spec;
  return nullptr;
}

std::string av_error(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {0};
  av_strerror(code, text, sizeof(text));
  return text;
}

// What one movie is encoded with.
struct Choice {
  const EncoderSpec *spec = nullptr;
  const char *encoder = nullptr;  // differs from spec->encoder for lossless h264
  AVPixelFormat pixels = AV_PIX_FMT_YUV420P;
  int quality = 0;
};

Status config_error(const std::string &key, const std::string &what) {
  return {StatusCode::kConfig, "output.movie." + key + ": " + what};
}

// Resolves codec, encoder, pixel format and quality; kConfig naming the key on any mismatch.
Status choose(const MovieConfig &movie, const std::string &path, Choice *out) {
  const std::string muxer = muxer_for(path);
  const EncoderSpec *spec = nullptr;
  if (movie.codec == "auto") {
    const bool webm = muxer == "webm";
    for (const char *family :
         webm ? std::vector<const char *>(std::begin(kAutoWebm), std::end(kAutoWebm))
              : std::vector<const char *>(std::begin(kAutoMpeg4), std::end(kAutoMpeg4)))
      if ((spec = first_present(family))) break;
    if (!spec)
      return config_error("codec", "auto found no encoder for " + extension_of(path) +
                                       " in this build; it has: " + movie_codecs_available());
  } else {
    bool known = false;
    for (const EncoderSpec &s : kEncoders) known = known || movie.codec == s.family;
    if (!known || !(spec = first_present(movie.codec.c_str())))
      return config_error("codec", "'" + movie.codec + "' is not " +
                                       (known ? "in this build" : "a codec Lantern encodes") +
                                       "; this build has: " + movie_codecs_available() +
                                       " (or auto)");
  }
  Choice c;
  c.spec = spec;
  c.encoder = spec->encoder;
  const std::string family = spec->family;
  if (family == "ffv1") {
    if (movie.quality)
      return config_error("quality", "ffv1 is lossless and takes no quality (remove the key)");
    c.pixels = AV_PIX_FMT_BGR0;
  } else if (movie.lossless) {
    if (family == "h264") {
      c.encoder = "libx264rgb";
      c.pixels = AV_PIX_FMT_RGB24;
      if (!avcodec_find_encoder_by_name(c.encoder))
        return config_error("lossless", "lossless h264 needs libx264rgb, which this build lacks");
    } else if (family == "hevc" || family == "vp9") {
      c.pixels = AV_PIX_FMT_GBRP;
    } else {
      return config_error("lossless", "not offered for " + family +
                                          " here; lossless codecs: h264, hevc, vp9, ffv1");
    }
  } else {
    c.quality = movie.quality.value_or(spec->default_quality);
    if (c.quality > spec->max_quality)
      return config_error("quality", std::to_string(c.quality) + " is beyond " + family +
                                         "'s range 0.." + std::to_string(spec->max_quality));
  }
  // The container must hold the codec (ffv1 goes in Matroska only, for one).
  const AVOutputFormat *format = av_guess_format(muxer.c_str(), nullptr, nullptr);
  const AVCodec *codec = avcodec_find_encoder_by_name(c.encoder);
  if (!format || !codec || avformat_query_codec(format, codec->id, FF_COMPLIANCE_NORMAL) != 1)
    return config_error("codec", family + " cannot be stored in " + extension_of(path) + " files" +
                                     (family == "ffv1" ? "; use .mkv" : "; use .mkv or .mp4"));
  *out = c;
  return {};
}

// The encoder's private options: fast presets, no look-ahead or frame reordering (so each frame
// reaches the file when it is encoded), the quality or lossless switch, and quiet logs.
void encoder_options(const Choice &c, AVDictionary **options) {
  const std::string encoder = c.encoder;
  const std::string quality = std::to_string(c.quality);
  const bool lossless = c.pixels != AV_PIX_FMT_YUV420P;
  if (encoder == "libx264" || encoder == "libx264rgb") {
    av_dict_set(options, "preset", "veryfast", 0);
    av_dict_set(options, "tune", "zerolatency", 0);
    av_dict_set(options, lossless ? "qp" : "crf", lossless ? "0" : quality.c_str(), 0);
    av_dict_set(options, "x264-params", "log=0", 0);  // x264's own log: errors only
  } else if (encoder == "libx265") {
    av_dict_set(options, "preset", "ultrafast", 0);
    av_dict_set(options, "tune", "zerolatency", 0);
    av_dict_set(options, "x265-params", lossless ? "log-level=error:lossless=1" : "log-level=error",
                0);
    if (!lossless) av_dict_set(options, "crf", quality.c_str(), 0);
  } else if (encoder == "libvpx-vp9") {
    av_dict_set(options, "deadline", "realtime", 0);
    av_dict_set(options, "cpu-used", "8", 0);
    av_dict_set(options, "lag-in-frames", "0", 0);
    av_dict_set(options, "row-mt", "1", 0);
    if (lossless)
      av_dict_set(options, "lossless", "1", 0);
    else
      av_dict_set(options, "crf", quality.c_str(), 0);
  } else if (encoder == "libaom-av1") {
    av_dict_set(options, "usage", "realtime", 0);
    av_dict_set(options, "cpu-used", "8", 0);
    av_dict_set(options, "lag-in-frames", "0", 0);
    av_dict_set(options, "crf", quality.c_str(), 0);
  } else if (encoder == "libsvtav1") {
    av_dict_set(options, "preset", "10", 0);
    av_dict_set(options, "crf", quality.c_str(), 0);
  } else if (encoder == "ffv1") {
    av_dict_set(options, "level", "3", 0);
    av_dict_set(options, "slicecrc", "1", 0);
  }
}

}  // namespace

bool movie_support_built() {
  return true;
}

std::string movie_codecs_available() {
  std::string out;
  std::string last_family;
  for (const EncoderSpec &spec : kEncoders) {
    if (!avcodec_find_encoder_by_name(spec.encoder)) continue;
    if (spec.family == last_family) {  // another encoder of the same family: a fallback
      out.insert(out.size() - 1, std::string(", ") + spec.encoder);
      continue;
    }
    out += (out.empty() ? "" : ", ") + std::string(spec.family) + " (" + spec.encoder + ")";
    last_family = spec.family;
  }
  return out.empty() ? "no encoder Lantern uses" : out;
}

Status check_movie_config(const MovieConfig &movie, const std::string &path) {
  Choice c;
  return choose(movie, path, &c);
}

struct MovieEncoder::Impl {
  std::string path;
  std::string encoder;
  int width = 0, height = 0;              // the images
  int coded_width = 0, coded_height = 0;  // the movie (padded for yuv420p)
  AVFormatContext *format = nullptr;
  AVCodecContext *codec = nullptr;
  AVStream *stream = nullptr;
  SwsContext *scale = nullptr;
  AVFrame *frame = nullptr;
  AVPacket *packet = nullptr;
  std::vector<uint8_t> padded;  // odd sizes in yuv420p: the image with its edge repeated
  int64_t written = 0;
  bool finished = false;
  bool header_written = false;

  ~Impl() {
    if (format && format->pb) avio_closep(&format->pb);
    avformat_free_context(format);
    avcodec_free_context(&codec);
    sws_freeContext(scale);
    av_frame_free(&frame);
    av_packet_free(&packet);
  }

  Status io_error(const std::string &what, int code) const {
    return {StatusCode::kIo, "movie '" + path + "': " + what + ": " + av_error(code)};
  }

  // Writes the packets the encoder has ready and flushes them to the file.
  Status drain() {
    for (;;) {
      const int received = avcodec_receive_packet(codec, packet);
      if (received == AVERROR(EAGAIN) || received == AVERROR_EOF) break;
      if (received < 0) return io_error("encoding", received);
      av_packet_rescale_ts(packet, codec->time_base, stream->time_base);
      packet->stream_index = stream->index;
      const int muxed = av_write_frame(format, packet);  // takes the packet's data
      av_packet_unref(packet);
      if (muxed < 0) return io_error("writing a frame", muxed);
      ++written;
    }
    // A NULL packet ends the fragment (MPEG-4) or cluster (Matroska) so it reaches the file now.
    const int flushed = av_write_frame(format, nullptr);
    if (flushed < 0) return io_error("flushing", flushed);
    avio_flush(format->pb);
    if (format->pb->error < 0) return io_error("flushing", format->pb->error);
    return {};
  }

  // The image in the coded size: the source itself, or the padded copy.
  const uint8_t *coded_pixels(const uint8_t *rgba) {
    if (coded_width == width && coded_height == height) return rgba;
    const size_t row = size_t(width) * 4, coded_row = size_t(coded_width) * 4;
    for (int y = 0; y < coded_height; ++y) {
      uint8_t *out = padded.data() + size_t(y) * coded_row;
      std::memcpy(out, rgba + size_t(std::min(y, height - 1)) * row, row);
      if (coded_width > width) std::memcpy(out + row, out + row - 4, 4);
    }
    return padded.data();
  }
};

MovieEncoder::MovieEncoder(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
MovieEncoder::~MovieEncoder() = default;

Status MovieEncoder::open(const MovieConfig &movie, const std::string &path, int width, int height,
                          std::unique_ptr<MovieEncoder> *out) {
  Choice choice;
  if (Status s = choose(movie, path, &choice); !s.ok()) return s;
  if (width < 1 || height < 1)
    return {StatusCode::kInvalidArgument, "movie '" + path + "': empty frame size"};
  auto m = std::make_unique<Impl>();
  m->path = path;
  m->encoder = choice.encoder;
  m->width = width;
  m->height = height;
  const bool subsampled = choice.pixels == AV_PIX_FMT_YUV420P;
  m->coded_width = subsampled ? width + (width & 1) : width;
  m->coded_height = subsampled ? height + (height & 1) : height;
  if (m->coded_width != width || m->coded_height != height)
    m->padded.resize(size_t(m->coded_width) * size_t(m->coded_height) * 4);

  const std::string muxer = muxer_for(path);
  if (avformat_alloc_output_context2(&m->format, nullptr, muxer.c_str(), path.c_str()) < 0 ||
      !m->format)
    return {StatusCode::kInternal, "movie '" + path + "': no " + muxer + " muxer"};
  const AVCodec *codec = avcodec_find_encoder_by_name(choice.encoder);
  m->stream = avformat_new_stream(m->format, nullptr);
  m->codec = avcodec_alloc_context3(codec);
  m->frame = av_frame_alloc();
  m->packet = av_packet_alloc();
  if (!m->stream || !m->codec || !m->frame || !m->packet)
    return {StatusCode::kOutOfMemory, "movie '" + path + "': out of memory"};

  AVCodecContext *cc = m->codec;
  const AVRational rate = av_d2q(movie.fps, 100000);
  cc->width = m->coded_width;
  cc->height = m->coded_height;
  cc->pix_fmt = choice.pixels;
  cc->time_base = av_inv_q(rate);
  cc->framerate = rate;
  cc->sample_aspect_ratio = AVRational{1, 1};
  cc->gop_size = std::max(1, int(std::lround(2.0 * movie.fps)));  // a key frame every 2 s
  cc->max_b_frames = 0;
  cc->thread_count = movie.threads;
  if (std::string(choice.encoder) == "libvpx-vp9" || std::string(choice.encoder) == "libaom-av1")
    cc->bit_rate = 0;  // constant quality (CRF) without a bit-rate cap
  if (subsampled) {
    cc->colorspace = AVCOL_SPC_BT709;
    cc->color_primaries = AVCOL_PRI_BT709;
    cc->color_trc = AVCOL_TRC_IEC61966_2_1;  // the images are sRGB
    cc->color_range = AVCOL_RANGE_MPEG;
  } else {
    cc->colorspace = AVCOL_SPC_RGB;
    cc->color_primaries = AVCOL_PRI_BT709;
    cc->color_trc = AVCOL_TRC_IEC61966_2_1;
    cc->color_range = AVCOL_RANGE_JPEG;
  }
  if (m->format->oformat->flags & AVFMT_GLOBALHEADER) cc->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  AVDictionary *options = nullptr;
  encoder_options(choice, &options);
  const int opened = avcodec_open2(cc, codec, &options);
  std::string unused;
  for (const AVDictionaryEntry *e = nullptr;
       (e = av_dict_get(options, "", e, AV_DICT_IGNORE_SUFFIX));)
    unused += std::string(unused.empty() ? "" : ", ") + e->key;
  av_dict_free(&options);
  if (opened < 0)
    return {StatusCode::kConfig, "movie '" + path + "': " + choice.encoder +
                                     " refused the settings: " + av_error(opened)};
  if (!unused.empty())
    return {StatusCode::kInternal,
            "movie '" + path + "': " + choice.encoder + " does not take the options " + unused};
  if (avcodec_parameters_from_context(m->stream->codecpar, cc) < 0)
    return {StatusCode::kInternal, "movie '" + path + "': codec parameters"};
  m->stream->time_base = cc->time_base;
  m->stream->avg_frame_rate = rate;

  m->frame->format = cc->pix_fmt;
  m->frame->width = cc->width;
  m->frame->height = cc->height;
  if (av_frame_get_buffer(m->frame, 0) < 0)
    return {StatusCode::kOutOfMemory, "movie '" + path + "': out of memory"};
  m->scale = sws_getContext(cc->width, cc->height, AV_PIX_FMT_RGBA, cc->width, cc->height,
                            cc->pix_fmt, SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INP,
                            nullptr, nullptr, nullptr);
  if (!m->scale) return {StatusCode::kInternal, "movie '" + path + "': no pixel conversion"};
  if (subsampled)  // BT.709 coefficients (swscale's default is BT.601), limited range
    sws_setColorspaceDetails(m->scale, sws_getCoefficients(SWS_CS_ITU709), 1,
                             sws_getCoefficients(SWS_CS_ITU709), 0, 0, 1 << 16, 1 << 16);

  if (Status s = create_parent_directories(path); !s.ok()) return s;
  if (const int e = avio_open(&m->format->pb, path.c_str(), AVIO_FLAG_WRITE); e < 0)
    return m->io_error("cannot open for writing", e);
  AVDictionary *mux = nullptr;
  if (fragmented_mpeg4(muxer))  // playable at every moment: fragments, the index up front
    av_dict_set(&mux, "movflags", "frag_keyframe+empty_moov+default_base_moof", 0);
  const int header = avformat_write_header(m->format, &mux);
  av_dict_free(&mux);
  if (header < 0) return m->io_error("writing the header", header);
  m->header_written = true;
  avio_flush(m->format->pb);
  if (m->format->pb->error < 0) return m->io_error("writing the header", m->format->pb->error);
  *out = std::unique_ptr<MovieEncoder>(new MovieEncoder(std::move(m)));
  return {};
}

Status MovieEncoder::encode(const uint8_t *rgba, int64_t index) {
  Impl &m = *impl_;
  if (m.finished) return {StatusCode::kInvalidArgument, "movie '" + m.path + "': finished"};
  if (const int e = av_frame_make_writable(m.frame); e < 0) return m.io_error("frame buffer", e);
  const uint8_t *source = m.coded_pixels(rgba);
  const uint8_t *planes[1] = {source};
  const int strides[1] = {m.coded_width * 4};
  sws_scale(m.scale, planes, strides, 0, m.coded_height, m.frame->data, m.frame->linesize);
  m.frame->pts = index;
  if (const int e = avcodec_send_frame(m.codec, m.frame); e < 0) return m.io_error("encoding", e);
  return m.drain();
}

int64_t MovieEncoder::frames_written() const {
  return impl_->written;
}

Status MovieEncoder::finish() {
  Impl &m = *impl_;
  if (m.finished) return {};
  m.finished = true;
  if (const int e = avcodec_send_frame(m.codec, nullptr); e < 0) return m.io_error("encoding", e);
  if (Status s = m.drain(); !s.ok()) return s;
  if (const int e = av_write_trailer(m.format); e < 0) return m.io_error("writing the index", e);
  if (const int e = avio_closep(&m.format->pb); e < 0) return m.io_error("closing", e);
  return {};
}

const std::string &MovieEncoder::encoder_name() const {
  return impl_->encoder;
}
int MovieEncoder::coded_width() const {
  return impl_->coded_width;
}
int MovieEncoder::coded_height() const {
  return impl_->coded_height;
}

}  // namespace lantern
