// lantern-bench-png: what writing a rendered frame as PNG costs, through OpenImageIO (as
// core/output/image_writer does: RGBA8, zlib level 1) and through png_bands.h on 1 and 2
// threads, plus the per-band time an MPI rank would pay, and a filter x strategy table that
// justifies png_bands' defaults. Every file is decoded again with OpenImageIO and compared with
// the frame. The frame is synthesised: a white background and an fcc crystal slab of shaded
// spheres (radius ~2.7 px) covering ~60% of the image, as Lantern renders one.
//   lantern-bench-png [--size 1024] [--runs 7] [--level 1] [--colored] [--image frame.png]
//                     [--save out.png]
// --colored gives every atom its own color (default: one color); --image benchmarks a real
// rendered frame (any 8-bit image OIIO reads) instead of the synthetic one; --save writes the frame
// used (as PNG) for a look.
#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "core/common/ms_since.h"
#include "core/output/atomic_file.h"
#include "core/output/image_writer.h"
#include "core/output/png/png_bands.h"
#include "core/view/frame.h"
#include "tests/support/hash_noise.h"

using namespace lantern;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Median wall time of `runs` calls, in milliseconds.
double time_ms(int runs, const std::function<void()> &f) {
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) {
    const auto start = std::chrono::steady_clock::now();
    f();
    t.push_back(ms_since(start));
  }
  return median(t);
}

using lantern::testing::hash;  // the tests' integer hash (tests/support/hash_noise.h)

// An fcc slab (2 cells deep) seen at an angle, orthographic, z-buffered, Lambert + specular
// shading. One color for all atoms (Lantern's default), or with `colored` a color per atom
// from a smooth ramp plus per-atom jitter (like coloring by a noisy per-atom quantity), which
// defeats LZ77 matches between repeated sphere sprites. Returns the frame and sets *coverage
// (fraction of non-background pixels) and *spheres (atoms drawn).
Frame render_crystal(int size, bool colored, double *coverage, int *spheres) {
  Frame f(size, size);
  const uint8_t bg[4] = {255, 255, 255, 255};
  f.clear(bg);
  const float radius = 2.7f * size / 1024.0f;
  const float a = 2.0f * radius * std::sqrt(2.0f);  // nearest neighbours just touch
  const int cells = int(0.81f * size / a);          // slab side ~81% of the image
  const int depth_cells = 2;
  const float basis[4][3] = {{0, 0, 0}, {0.5f, 0.5f, 0}, {0.5f, 0, 0.5f}, {0, 0.5f, 0.5f}};
  const float ay = 0.35f, ax = 0.25f;  // rotations about y, then x (radians)
  const float cy = std::cos(ay), sy = std::sin(ay), cx = std::cos(ax), sx = std::sin(ax);
  const float half = 0.5f * cells * a;
  const float light[3] = {-0.4f, 0.5f, 0.77f};
  int count = 0;
  for (int i = 0; i < cells; ++i)
    for (int j = 0; j < cells; ++j)
      for (int k = 0; k < depth_cells; ++k)
        for (const auto &b : basis) {
          const float p[3] = {(i + b[0]) * a - half, (j + b[1]) * a - half,
                              (k + b[2]) * a - 0.5f * depth_cells * a};
          // Rotate: about y, then about x. Screen x right, y down, z towards the viewer.
          const float x1 = cy * p[0] + sy * p[2], z1 = -sy * p[0] + cy * p[2];
          const float y2 = cx * p[1] - sx * z1, z2 = sx * p[1] + cx * z1;
          const float px = 0.5f * size + x1, py = 0.5f * size + y2;
          // Color: a smooth ramp across the slab (like coloring by a coordinate or a slowly
          // varying field) with +-8% per-atom jitter (thermal noise in the colored quantity).
          const float t = !colored
                              ? 0.35f
                              : std::clamp(float(i) / cells * 0.8f +
                                               0.2f * float(hash(uint32_t(count)) % 1000) / 1000.0f,
                                           0.0f, 1.0f);
          const float base[3] = {0.15f + 0.8f * t, 0.3f + 0.4f * std::sin(3.1f * t),
                                 0.9f - 0.7f * t};
          ++count;
          const int x0 = int(std::floor(px - radius)), x1i = int(std::ceil(px + radius));
          const int y0 = int(std::floor(py - radius)), y1i = int(std::ceil(py + radius));
          for (int y = std::max(y0, 0); y <= std::min(y1i, size - 1); ++y)
            for (int x = std::max(x0, 0); x <= std::min(x1i, size - 1); ++x) {
              const float dx = (x + 0.5f - px) / radius, dy = (y + 0.5f - py) / radius;
              const float d2 = dx * dx + dy * dy;
              if (d2 > 1.0f) continue;
              const float nz = std::sqrt(1.0f - d2);
              const float zdepth = 0.5f - (z2 + nz * radius) / (4.0f * size);  // smaller = nearer
              const size_t idx = f.index(x, y);
              if (zdepth >= f.depth[idx]) continue;
              f.depth[idx] = zdepth;
              const float diffuse =
                  std::max(0.0f, dx * light[0] - dy * light[1] + nz * light[2]);  // n . l
              const float spec = std::pow(std::max(0.0f, nz * 0.95f + diffuse * 0.05f), 40.0f);
              for (int c = 0; c < 3; ++c) {
                const float v = base[c] * (0.25f + 0.75f * diffuse) + 0.35f * spec;
                f.rgba[4 * idx + c] = uint8_t(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f);
              }
              f.rgba[4 * idx + 3] = 255;
            }
        }
  size_t covered = 0;
  for (float d : f.depth) covered += d < kBackgroundDepth;
  *coverage = double(covered) / double(f.pixel_count());
  *spheres = count;
  return f;
}

// Loads an image file as an RGBA8 frame (alpha 255 if the file has none). "" or a message.
std::string load_frame(const std::string &path, Frame *f) {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path, &config);
  if (!in) return "cannot open " + path + ": " + OIIO::geterror();
  const OIIO::ImageSpec &spec = in->spec();
  const int channels = std::min(spec.nchannels, 4);
  std::vector<uint8_t> px(size_t(spec.width) * spec.height * size_t(channels));
  if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, px.data()))
    return "cannot read " + path + ": " + in->geterror();
  *f = Frame(spec.width, spec.height);
  for (size_t i = 0; i < f->pixel_count(); ++i)
    for (size_t c = 0; c < 4; ++c) {
      const size_t from = channels >= 3 ? c : 0;  // grey: replicated
      f->rgba[4 * i + c] = c == 3 && channels != 4 ? 255 : px[i * size_t(channels) + from];
    }
  return "";
}

// Reads `path` with OpenImageIO (raw bytes, no premultiplication) and compares with the frame's
// RGBA or RGB bytes. "" if equal, else what differs.
std::string decode_check(const std::string &path, const Frame &f, int channels) {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path, &config);
  if (!in) return "cannot open: " + OIIO::geterror();
  const OIIO::ImageSpec &spec = in->spec();
  if (spec.width != f.width || spec.height != f.height || spec.nchannels != channels)
    return "wrong size or channel count";
  std::vector<uint8_t> px(f.pixel_count() * size_t(channels));
  if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, px.data()))
    return "cannot read: " + in->geterror();
  for (size_t i = 0; i < f.pixel_count(); ++i)
    for (int c = 0; c < channels; ++c)
      if (px[i * size_t(channels) + size_t(c)] != f.rgba[4 * i + size_t(c)])
        return "pixel " + std::to_string(i) + " differs";
  return "";
}

std::string save(const std::string &path, const std::vector<uint8_t> &bytes) {
  return write_bytes_atomically(path, bytes.data(), bytes.size()).message;
}

const char *filter_name(PngFilter f) {
  static const char *names[] = {"None", "Sub", "Up", "Average", "Paeth"};
  return names[int(f)];
}

const char *strategy_name(PngStrategy s) {
  static const char *names[] = {"runs (lantern)", "default", "filtered", "rle", "huffman"};
  return names[int(s)];
}

}  // namespace

int main(int argc, char **argv) {
  int size = 1024, runs = 7, level = 1;
  std::string image, save_as;
  bool colored = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const char *value = i + 1 < argc ? argv[i + 1] : nullptr;
    if (arg == "--colored") {
      colored = true;
      continue;
    }
    if (!value || (arg != "--size" && arg != "--runs" && arg != "--level" && arg != "--image" &&
                   arg != "--save")) {
      std::fprintf(stderr, "lantern-bench-png: unknown or incomplete option '%s'\n", arg.c_str());
      return 2;
    }
    ++i;
    if (arg == "--size") size = std::max(1, std::atoi(value));
    if (arg == "--runs") runs = std::max(1, std::atoi(value));
    if (arg == "--level") level = std::atoi(value);
    if (arg == "--image") image = value;
    if (arg == "--save") save_as = value;
  }
  double coverage = 0;
  int spheres = 0;
  Frame frame;
  if (image.empty()) {
    frame = render_crystal(size, colored, &coverage, &spheres);
  } else {
    const std::string error = load_frame(image, &frame);
    if (!error.empty()) {
      std::fprintf(stderr, "lantern-bench-png: %s\n", error.c_str());
      return 1;
    }
  }
  const int width = frame.width, height = frame.height;
  if (!save_as.empty()) {
    std::vector<uint8_t> png;
    encode_png(frame.rgba.data(), width, height, 4, 6, 1, &png);
    save(save_as, png);
  }
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("lantern-bench-png-" + std::to_string(getpid())))
          .string();
  std::filesystem::create_directories(dir);
  const uint8_t *rgba = frame.rgba.data();
  if (image.empty())
    std::printf("%dx%d synthetic frame (%s): %d spheres of radius %.1f px drawn, %.0f%% covered",
                width, height, colored ? "color per atom" : "one color", spheres,
                2.7 * size / 1024.0, 100 * coverage);
  else
    std::printf("%dx%d frame from %s", width, height, image.c_str());
  std::printf("; zlib level %d; median of %d runs\n\n", level, runs);

  // (a) OpenImageIO (libpng), as image_writer wrote PNG before png_bands: RGBA8, unassociated
  // alpha, png:compressionLevel.
  const std::string oiio_path = dir + "/oiio.png";
  std::string error;
  const auto write_with_oiio = [&] {
    auto output = OIIO::ImageOutput::create(oiio_path);
    if (!output) return std::string("OpenImageIO cannot create a PNG writer");
    OIIO::ImageSpec spec(frame.width, frame.height, 4, OIIO::TypeDesc::UINT8);
    spec.alpha_channel = 3;
    spec.attribute("oiio:UnassociatedAlpha", 1);
    spec.attribute("png:compressionLevel", level);
    if (!output->open(oiio_path, spec) ||
        !output->write_image(OIIO::TypeDesc::UINT8, frame.rgba.data()) || !output->close())
      return output->geterror();
    return std::string();
  };
  const double oiio_ms = time_ms(runs, [&] { error = write_with_oiio(); });
  if (!error.empty()) {
    std::fprintf(stderr, "lantern-bench-png: %s\n", error.c_str());
    return 1;
  }
  const double oiio_kib = double(std::filesystem::file_size(oiio_path)) / 1024.0;
  const std::string oiio_check = decode_check(oiio_path, frame, 4);

  std::printf("%-34s %9s %10s %9s %8s %8s  %s\n", "method (RGBA unless noted)", "encode ms",
              "+write ms", "KiB", "size", "speed-up", "decoded == frame");
  std::printf("%-34s %9s %10.2f %9.1f %7.2fx %7.2fx  %s\n", "(a) OIIO write_image (libpng)", "-",
              oiio_ms, oiio_kib, 1.0, 1.0, oiio_check.empty() ? "yes" : oiio_check.c_str());

  bool all_equal = oiio_check.empty();
  const auto row = [&](const char *name, int channels, int threads) {
    std::vector<uint8_t> file;
    const double enc =
        time_ms(runs, [&] { encode_png(rgba, width, height, channels, level, threads, &file); });
    const std::string path =
        dir + "/bands" + std::to_string(threads) + "_" + std::to_string(channels) + ".png";
    const double total = time_ms(runs, [&] {
      encode_png(rgba, width, height, channels, level, threads, &file);
      save(path, file);
    });
    const std::string check = decode_check(path, frame, channels);
    all_equal = all_equal && check.empty();
    const double kib = double(file.size()) / 1024.0;
    std::printf("%-34s %9.2f %10.2f %9.1f %7.2fx %7.2fx  %s\n", name, enc, total, kib,
                kib / oiio_kib, oiio_ms / total, check.empty() ? "yes" : check.c_str());
  };
  row("(b) encode_png, 1 thread", 4, 1);
  row("(c) encode_png, 2 threads", 4, 2);
  row("    encode_png, 1 thread, RGB", 3, 1);
  row("    encode_png, 2 threads, RGB", 3, 2);

  // Per band, as one MPI rank would pay it: each band compressed alone on one thread, then the
  // root's assembly (concatenation, adler32_combine, CRCs).
  for (int bands : {2, 4}) {
    std::printf("\n%d bands (RGBA), each compressed alone, as %d MPI ranks would:\n", bands, bands);
    std::vector<PngBand> pieces(size_t(bands), PngBand{});
    const size_t stride = size_t(width) * 4;
    double slowest = 0;
    for (int b = 0; b < bands; ++b) {
      const int y0 = height * b / bands, y1 = height * (b + 1) / bands;
      const uint8_t *first = rgba + size_t(y0) * stride;
      const double ms = time_ms(runs, [&] {
        if (Status s = deflate_png_band(first, width, y1 - y0, 4, b + 1 == bands, level,
                                        &pieces[size_t(b)], y0 > 0 ? first - stride : nullptr);
            !s.ok())
          std::fprintf(stderr, "lantern-bench-png: %s\n", s.message.c_str());
      });
      slowest = std::max(slowest, ms);
      std::printf("  band %d (rows %4d..%4d): %6.2f ms, %7.1f KiB\n", b, y0, y1 - 1, ms,
                  pieces[size_t(b)].bytes.size() / 1024.0);
    }
    std::vector<uint8_t> file;
    const double assemble_ms = time_ms(runs, [&] {
      if (Status s = assemble_png(pieces, width, height, 4, &file); !s.ok())
        std::fprintf(stderr, "assemble_png: %s\n", s.message.c_str());
    });
    const std::string path = dir + "/ranks" + std::to_string(bands) + ".png";
    save(path, file);
    const std::string check = decode_check(path, frame, 4);
    all_equal = all_equal && check.empty();
    std::printf(
        "  root assembly: %.2f ms; slowest band + assembly %.2f ms (%.1fx OIIO); "
        "%.1f KiB; decoded == frame: %s\n",
        assemble_ms, slowest + assemble_ms, oiio_ms / (slowest + assemble_ms), file.size() / 1024.0,
        check.empty() ? "yes" : check.c_str());
  }

  // Filter x strategy, 1 thread, RGBA, encode only: why png_bands uses Sub + its own runs.
  std::printf(
      "\nfilter x strategy (Lantern's runs, then zlib's), 1 thread, RGBA, encode only "
      "(ms / KiB / size vs OIIO):\n");
  std::printf("%-8s", "");
  const PngStrategy strategies[] = {PngStrategy::kRuns, PngStrategy::kDefault,
                                    PngStrategy::kFiltered, PngStrategy::kRle,
                                    PngStrategy::kHuffmanOnly};
  for (PngStrategy s : strategies) std::printf(" %24s", strategy_name(s));
  std::printf("\n");
  for (PngFilter f : {PngFilter::kNone, PngFilter::kSub, PngFilter::kUp, PngFilter::kAverage,
                      PngFilter::kPaeth}) {
    std::printf("%-8s", filter_name(f));
    for (PngStrategy s : strategies) {
      PngBandOptions options;
      options.filter = f;
      options.strategy = s;
      std::vector<uint8_t> file;
      const double ms =
          time_ms(runs, [&] { encode_png(rgba, width, height, 4, level, 1, &file, options); });
      const std::string path = dir + "/grid.png";
      save(path, file);
      all_equal = all_equal && decode_check(path, frame, 4).empty();
      char cell[64];
      std::snprintf(cell, sizeof cell, "%.2f / %.0f / %.2fx", ms, file.size() / 1024.0,
                    file.size() / 1024.0 / oiio_kib);
      std::printf(" %24s", cell);
    }
    std::printf("\n");
  }
  std::printf("\nall decoded files equal the frame: %s\n", all_equal ? "yes" : "NO");
  std::filesystem::remove_all(dir);
  return all_equal ? 0 : 1;
}
