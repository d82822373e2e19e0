// movie_encoder.h in a build without FFmpeg's libraries: a `movie:` section is a configuration
// error that says so, at lantern_open. No MovieEncoder is ever made.
#include "core/output/movie/movie_encoder.h"

namespace lantern {

namespace {

Status lacking() {
  return {StatusCode::kConfig,
          "output.movie: this Lantern was built without movie support (FFmpeg's libavcodec, "
          "libavformat, libavutil and libswscale were not found, or LANTERN_WITH_MOVIE=OFF); "
          "rebuild with them (Debian: libavcodec-dev libavformat-dev libavutil-dev "
          "libswscale-dev) or write images (output.pattern)"};
}

}  // namespace

struct MovieEncoder::Impl {};

bool movie_support_built() {
  return false;
}
std::string movie_codecs_available() {
  return "none (built without movie support)";
}
Status check_movie_config(const MovieConfig &, const std::string &) {
  return lacking();
}

MovieEncoder::MovieEncoder(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
MovieEncoder::~MovieEncoder() = default;

Status MovieEncoder::open(const MovieConfig &, const std::string &, int, int,
                          std::unique_ptr<MovieEncoder> *) {
  return lacking();
}

// Unreachable: open() never makes an encoder in this build.
Status MovieEncoder::encode(const uint8_t *, int64_t) {
  return lacking();
}
int64_t MovieEncoder::frames_written() const {
  return 0;
}
Status MovieEncoder::finish() {
  return lacking();
}
const std::string &MovieEncoder::encoder_name() const {
  static const std::string kNone = "none";
  return kNone;
}
int MovieEncoder::coded_width() const {
  return 0;
}
int MovieEncoder::coded_height() const {
  return 0;
}

}  // namespace lantern
