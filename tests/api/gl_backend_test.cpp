// The OpenGL back ends through the C API: EGL and OSMesa give byte-identical images (both are
// llvmpipe here), `gl: none` / LANTERN_GL=none draws every scene - every example configuration
// too - with the CPU raster, renderer: opengl without GL and an unknown LANTERN_GL are errors
// that name the key or variable, and an EGL device that cannot be had falls back.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "tests/api/api_fixture.h"
#include "tests/support/image_file.h"

namespace lantern::testing {
namespace {

// Sets an environment variable for one scope (tests in this file run in one process, serially).
class ScopedEnv {
 public:
  ScopedEnv(const char *name, const char *value) : name_(name) {
    if (const char *old = std::getenv(name)) old_ = old, had_ = true;
    setenv(name, value, 1);
  }
  ~ScopedEnv() { had_ ? setenv(name_, old_.c_str(), 1) : unsetenv(name_); }

 private:
  const char *name_;
  std::string old_;
  bool had_ = false;
};

class GlBackends : public ApiTest {
 protected:
  void SetUp() override {
    ApiTest::SetUp();
    unsetenv("LANTERN_GL");  // the tests choose with the `gl` key unless they set it
    unsetenv("LANTERN_EGL_DEVICE");
  }

  // Renders `scene_yaml` (scene keys) once with `gl: <backend>` into <name>_0000.png and returns
  // the back end the step's stats line reports.
  std::string render(const std::string &backend, const std::string &name,
                     const std::string &scene_yaml, int w = 200, int h = 150) {
    std::filesystem::remove(dir_ / "stats.jsonl");
    const lantern_status st = open("gl: " + backend + "\n" + scene_config(name, w, h, scene_yaml));
    EXPECT_EQ(st, LANTERN_OK) << message();
    if (st != LANTERN_OK) return "";
    // Members, not locals: Lantern borrows them until the next publish or close, and a test may
    // execute the context again after render() returns.
    x_ = lattice(9);
    type_.assign(x_.size() / 3, 0);
    for (size_t i = 0; i < type_.size(); ++i) type_[i] = int32_t(i % 5);
    lantern_particles p = interleaved(x_);
    p.type = {type_.data(), LANTERN_INT32, 0};
    EXPECT_EQ(lantern_publish(ctx_, &p), LANTERN_OK) << message();
    EXPECT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
    return stats_field("gl");
  }

  std::string stats_field(const std::string &key, int scene = -1) const {
    std::ifstream in(dir_ / "stats.jsonl");
    std::string line, last;
    while (std::getline(in, line)) last = line;
    if (last.empty()) return "";
    const nlohmann::json j = nlohmann::json::parse(last);
    return scene < 0 ? j.value(key, "") : j["scenes"][size_t(scene)].value(key, "");
  }

  std::vector<double> x_;  // the published particles of render()
  std::vector<int32_t> type_;
};

const char *const kScenes[] = {
    "    renderer: opengl\n",
    "    renderer: opengl\n    camera: {projection: orthographic, azimuth: 10}\n",
    "    renderer: opengl\n    radius: 1.4\n    camera: {zoom: 3}\n",
    "    renderer: opengl\n    camera: {position: [4, 4, 4], look_at: [0, 0, 0], fov: 80}\n",
};

TEST_F(GlBackends, EglAndOsmesaGiveByteIdenticalImages) {
  int compared = 0;
  for (size_t k = 0; k < std::size(kScenes); ++k) {
    const std::string a = "egl" + std::to_string(k), b = "osmesa" + std::to_string(k);
    const std::string ran_egl = render("egl", a, kScenes[k]);
    const std::string ran_osmesa = render("osmesa", b, kScenes[k]);
    if (ran_egl != "egl" || ran_osmesa != "osmesa")
      GTEST_SKIP() << "this machine or build lacks a back end (ran " << ran_egl << " and "
                   << ran_osmesa << ")";
    const auto egl = read_bytes(png(a, 0)), osmesa = read_bytes(png(b, 0));
    ASSERT_GT(egl.size(), 500u);
    EXPECT_EQ(egl, osmesa) << "scene " << k;
    ++compared;
  }
  EXPECT_EQ(compared, int(std::size(kScenes)));
}

TEST_F(GlBackends, NoneDrawsWithTheCpuRasterAndSaysSo) {
  // Large spheres (auto would pick OpenGL) and nine-spheres culling (which the CPU raster does
  // not run): without GL both go to the CPU raster, culling exactly.
  ASSERT_EQ(render("none", "none", "    radius: 1.2\n    culling: {occlusion: nine_spheres}\n"),
            "none");
  EXPECT_EQ(stats_field("renderer", 0), "cpu");
  EXPECT_NE(stats_field("occlusion", 0).find("no OpenGL"), std::string::npos)
      << stats_field("occlusion", 0);
  // The same image as asking for the CPU raster with exact culling directly.
  ASSERT_EQ(
      render("none", "cpu", "    radius: 1.2\n    renderer: cpu\n    culling: {occlusion: hzb}\n"),
      "none");
  EXPECT_EQ(read_bytes(png("none", 0)), read_bytes(png("cpu", 0)));
}

TEST_F(GlBackends, RendererOpenglWithoutGlIsAConfigurationError) {
  EXPECT_EQ(open("gl: none\n" + scene_config("x", 64, 64, "    renderer: opengl\n")),
            LANTERN_ERR_CONFIG);
  EXPECT_NE(message().find("scenes 'x': renderer: opengl"), std::string::npos) << message();
}

TEST_F(GlBackends, EnvironmentWinsOverTheKeyAndIsChecked) {
  {
    const ScopedEnv env("LANTERN_GL", "none");
    EXPECT_EQ(render("egl", "env", ""), "none");
  }
  {
    const ScopedEnv env("LANTERN_GL", "vulkan");
    EXPECT_EQ(open(scene_config("x", 64, 64)), LANTERN_ERR_CONFIG);
    EXPECT_NE(message().find("LANTERN_GL: 'vulkan' is not one of auto, egl, osmesa, none"),
              std::string::npos)
        << message();
  }
  {
    const ScopedEnv env("LANTERN_EGL_DEVICE", "first");
    EXPECT_EQ(open(scene_config("x", 64, 64)), LANTERN_ERR_CONFIG);
    EXPECT_NE(message().find("LANTERN_EGL_DEVICE"), std::string::npos) << message();
  }
  EXPECT_EQ(open("gl: metal\n" + scene_config("x", 64, 64)), LANTERN_ERR_CONFIG);
  EXPECT_NE(message().find("gl: must be one of auto, egl, osmesa, none"), std::string::npos)
      << message();
}

TEST_F(GlBackends, AnEglDeviceThatCannotBeHadFallsBack) {
  // No machine here has 1000 EGL devices: the step still renders, through another back end.
  const std::string ran = render("egl", "dev", "", 64, 64);
  if (ran != "egl") GTEST_SKIP() << "no EGL here";
  {
    const ScopedEnv env("LANTERN_EGL_DEVICE", "1000");
    const std::string fallback = render("egl", "dev2", "", 64, 64);
    EXPECT_NE(fallback, "egl");
    EXPECT_FALSE(fallback.empty());
  }
}

// True if the configuration file sets `key` somewhere (outside comments).
bool uses_key(const std::filesystem::path &file, const std::string &key) {
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    line = line.substr(0, line.find('#'));
    const size_t at = line.find(key + ":");
    if (at != std::string::npos && (at == 0 || line[at - 1] == ' ' || line[at - 1] == '{'))
      return true;
  }
  return false;
}

// Every example configuration renders with LANTERN_GL=none (and so with the CPU raster alone).
TEST_F(GlBackends, EveryExampleConfigurationRendersWithoutGl) {
  const ScopedEnv env("LANTERN_GL", "none");
  const auto cwd = std::filesystem::current_path();
  std::filesystem::current_path(dir_);  // the examples write relative to the working directory
  std::vector<double> x = lattice(8);
  const size_t n = x.size() / 3;
  std::vector<double> radius(n, 0.45), scalar(n);
  std::vector<int32_t> type(n);
  std::vector<int64_t> id(n);
  for (size_t i = 0; i < n; ++i)
    scalar[i] = double(i % 17), type[i] = int32_t(i % 3), id[i] = int64_t(i);
  lantern_particles p = interleaved(x);
  p.radius = {radius.data(), LANTERN_FLOAT64, 0};
  p.scalar = {scalar.data(), LANTERN_FLOAT64, 0};
  p.type = {type.data(), LANTERN_INT32, 0};
  p.id = {id.data(), LANTERN_INT64, 0};
  int rendered = 0;
  for (const auto &entry : std::filesystem::directory_iterator(LANTERN_CONFIG_DIR)) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().filename().string());
    // A build without movies refuses a movie (tests/api/movie_test.cpp checks the message), one
    // without text refuses labels, legends and axes (tests/finish checks the message).
    const bool needs_movie = uses_key(entry.path(), "movie");
    const bool needs_text = uses_key(entry.path(), "labels") || uses_key(entry.path(), "legend") ||
                            uses_key(entry.path(), "axes");
    if ((needs_movie && !LANTERN_TEST_MOVIES) || (needs_text && !LANTERN_TEST_TEXT)) {
      EXPECT_EQ(open(entry.path().string()), LANTERN_ERR_CONFIG);
      continue;
    }
    ASSERT_EQ(open(entry.path().string()), LANTERN_OK) << message();
    ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK) << message();
    ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
    ++rendered;
  }
  lantern_close(ctx_);
  ctx_ = nullptr;
  int images = 0;
  for (const auto &f : std::filesystem::recursive_directory_iterator(dir_))
    images += f.path().extension() == ".png" || f.path().extension() == ".exr" ||
              f.path().extension() == ".mp4";
  std::filesystem::current_path(cwd);
  EXPECT_GE(rendered, 7);
  EXPECT_GE(images, rendered);
}

// A context opened on one thread and executed on another: EGL refuses to make the GL context
// current there (EGL_BAD_ACCESS, 0x3002), and the message says why instead of only the code.
TEST_F(GlBackends, ExecutingFromAnotherThreadSaysTheContextBelongsToTheOpener) {
  if (render("egl", "t", kScenes[0], 32, 32) != "egl") GTEST_SKIP() << "no EGL here";
  lantern_status st = LANTERN_OK;
  std::thread([&] { st = lantern_execute(ctx_, 1, 0.0); }).join();
  EXPECT_EQ(st, LANTERN_ERR_GL);
  EXPECT_NE(message().find("belongs to the thread that opened it"), std::string::npos) << message();
  EXPECT_EQ(lantern_execute(ctx_, 2, 0.0), LANTERN_OK) << message();  // the opener still can
}

}  // namespace
}  // namespace lantern::testing
