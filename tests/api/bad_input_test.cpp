// Every bad input the C API can get returns its status and a message naming the problem, and
// the context stays usable afterwards.
#include <fcntl.h>
#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <limits>

#include "tests/api/api_fixture.h"

namespace lantern::testing {
namespace {

using BadInput = ApiTest;

TEST_F(BadInput, NullArguments) {
  EXPECT_EQ(lantern_open(nullptr, LANTERN_COMM_WORLD, &ctx_), LANTERN_ERR_NULL_ARGUMENT);
  EXPECT_NE(message().find("config"), std::string::npos);
  EXPECT_EQ(lantern_open("scenes: [{}]", LANTERN_COMM_WORLD, nullptr), LANTERN_ERR_NULL_ARGUMENT);
  const lantern_particles p{};
  EXPECT_EQ(lantern_publish(nullptr, &p), LANTERN_ERR_NULL_ARGUMENT);
  EXPECT_EQ(lantern_execute(nullptr, 0, 0.0), LANTERN_ERR_NULL_ARGUMENT);
  EXPECT_STRNE(lantern_error_message(nullptr), "");
  EXPECT_EQ(lantern_close(nullptr), LANTERN_OK);
  ASSERT_EQ(open(scene_config("a")), LANTERN_OK) << message();
  EXPECT_EQ(lantern_publish(ctx_, nullptr), LANTERN_ERR_NULL_ARGUMENT);
  EXPECT_NE(message().find("particles"), std::string::npos);
}

TEST_F(BadInput, ParticleDescriptionsAreRejectedAndTheContextStaysUsable) {
  ASSERT_EQ(open(scene_config("p")), LANTERN_OK) << message();
  std::vector<double> x = lattice(3);
  const float radius_nan[1] = {std::numeric_limits<float>::quiet_NaN()};
  struct Case {
    const char *what;
    lantern_particles p;
    const char *names;
  };
  std::vector<Case> cases;
  lantern_particles p = interleaved(x);
  p.count = -1;
  cases.push_back({"negative count", p, "count"});
  p.count = int64_t(1) << 32;  // beyond the bricks' 32-bit indices (never read: refused first)
  cases.push_back({"2^32 particles on one rank", p, "count: 4294967296 on one rank"});
  p = interleaved(x);
  p.position.stride_bytes = 16;  // shorter than 3 doubles
  cases.push_back({"short stride", p, "stride_bytes"});
  p = interleaved(x);
  p.position.data = nullptr;
  cases.push_back({"null positions", p, "position"});
  p = interleaved(x);
  p.position.type = LANTERN_INT32;
  cases.push_back({"integer positions", p, "position.type"});
  p = interleaved(x);
  p.position_x = p.position;
  cases.push_back({"both layouts", p, "position"});
  p = interleaved(x);
  p.count = 1;
  p.radius = {radius_nan, LANTERN_FLOAT32, 0};
  cases.push_back({"NaN radius", p, "radius[0]"});
  const double negative[1] = {-0.5};
  p.radius = {negative, LANTERN_FLOAT64, 0};
  cases.push_back({"negative radius", p, "radius[0]"});
  for (const auto &c : cases) {
    EXPECT_EQ(lantern_publish(ctx_, &c.p), LANTERN_ERR_INVALID_ARGUMENT) << c.what;
    EXPECT_NE(message().find(c.names), std::string::npos) << c.what << ": " << message();
    // Still usable: a valid publish and a render work right after.
    const lantern_particles good = interleaved(x);
    ASSERT_EQ(lantern_publish(ctx_, &good), LANTERN_OK) << c.what;
    ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << c.what << ": " << message();
  }
}

TEST_F(BadInput, ConfigurationErrorsNameTheKey) {
  EXPECT_EQ(open("scenes:\n  - {width: 10\n"), LANTERN_ERR_CONFIG);
  EXPECT_NE(message().find("YAML"), std::string::npos) << message();
  EXPECT_EQ(open("scenes:\n  - widht: 10\n"), LANTERN_ERR_CONFIG);
  EXPECT_NE(message().find("widht"), std::string::npos) << message();
  EXPECT_NE(message().find("width"), std::string::npos) << message();  // the suggestion
  EXPECT_NE(message().find("line 2"), std::string::npos) << message();
  EXPECT_EQ(open("scenes:\n  - width: 0\n"), LANTERN_ERR_CONFIG);
  EXPECT_NE(message().find("width"), std::string::npos) << message();
  EXPECT_EQ(open("scenes:\n  - height: 100000\n"), LANTERN_ERR_CONFIG);
  EXPECT_NE(message().find("height"), std::string::npos) << message();
  EXPECT_EQ(open((dir_ / "missing.yaml").string()), LANTERN_ERR_CONFIG);
  EXPECT_NE(message().find("missing.yaml"), std::string::npos) << message();
  // A failed open still hands back a context holding the message; using it is an error, not a
  // crash.
  const lantern_particles p{};
  EXPECT_EQ(lantern_publish(ctx_, &p), LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_ERR_INVALID_ARGUMENT);
}

TEST_F(BadInput, SceneNeedsAnArrayThatWasNotPublished) {
  ASSERT_EQ(open(scene_config("s", 32, 32, "    color: {by: scalar}\n")), LANTERN_OK) << message();
  std::vector<double> x = lattice(2);
  const lantern_particles p = interleaved(x);
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  EXPECT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_NE(message().find("scalar"), std::string::npos) << message();
}

TEST_F(BadInput, UnwritableOutputFailsThatStepAndLaterStepsRetry) {
  // A directory that cannot be created: its parent is a regular file.
  const auto blocker = dir_ / "blocker";
  std::ofstream(blocker) << "not a directory";
  const std::string pattern = (blocker / "img_{step:04d}.png").string();
  ASSERT_EQ(
      open("scenes:\n  - width: 32\n    height: 32\n    output: {pattern: '" + pattern + "'}\n"),
      LANTERN_OK)
      << message();
  std::vector<double> x = lattice(2);
  const lantern_particles p = interleaved(x);
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  EXPECT_EQ(lantern_execute(ctx_, 1, 0.0), LANTERN_ERR_IO);
  EXPECT_NE(message().find("blocker"), std::string::npos) << message();
  // The simulation fixes the problem; the next step writes.
  std::filesystem::remove(blocker);
  EXPECT_EQ(lantern_execute(ctx_, 2, 0.0), LANTERN_OK) << message();
  EXPECT_TRUE(std::filesystem::exists(blocker / "img_0002.png"));
  // Nothing half-written is left behind: only the final image in the directory.
  int files = 0;
  for (const auto &e : std::filesystem::directory_iterator(blocker)) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
}

// Values too large to frame used to fail as "camera.near/far: need 0 < near <
// far", a key the user never set. Each now names its source, with the status that fits: data
// (published positions or radii) is an invalid argument, a configured value a configuration error.
TEST_F(BadInput, ValuesTooLargeToFrameNameTheirSource) {
  std::vector<double> x = lattice(2);
  lantern_particles p = interleaved(x);
  const auto execute = [&](const std::string &config, lantern_status expected,
                           const std::string &names) {
    ASSERT_EQ(open(config), LANTERN_OK) << message();
    ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK) << message();
    EXPECT_EQ(lantern_execute(ctx_, 0, 0.0), expected) << config << ": " << message();
    EXPECT_NE(message().find(names), std::string::npos) << message();
    EXPECT_EQ(message().find("near"), std::string::npos) << message();
  };
  // A finite coordinate of 1e155 among particles near the origin.
  x[0] = 1e155;
  execute(scene_config("far"), LANTERN_ERR_INVALID_ARGUMENT, "particles: positions reach 1e+155");
  x[0] = 0.0;
  execute(scene_config("big", 96, 64, "    radius: 1e200\n"), LANTERN_ERR_CONFIG,
          "scenes 'big': radius: 1e+200");
  execute(scene_config("zoomed", 96, 64, "    camera: {zoom: 1e300}\n"), LANTERN_ERR_CONFIG,
          "scenes 'zoomed': camera.zoom: 1e+300");
  // Per-particle radii are data.
  const double radii[8] = {0.5, 0.5, 0.5, 1e200, 0.5, 0.5, 0.5, 0.5};
  p.radius = {radii, LANTERN_FLOAT64, 0};
  execute(scene_config("each", 96, 64, "    radius: per_particle\n"), LANTERN_ERR_INVALID_ARGUMENT,
          "particles.radius: the largest radius, 1e+200");
  p.radius = {};
  // Large but framable: a scene 1e140 across still renders.
  for (double &v : x) v *= 1e140;
  ASSERT_EQ(open(scene_config("huge")), LANTERN_OK) << message();
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK) << message();
  EXPECT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
}

// Scales where single-precision stages lose the picture (measured: OpenGL blank with the scene's
// farthest point 3.3e19 from the eye, screen AO's normals wrong below a span of about 2e-8 and
// above 1e11) still render, but rank 0 says so once on stderr; a scene at unit scale says
// nothing.
TEST_F(BadInput, ScalesBeyondSinglePrecisionAreWarnedOfOnce) {
  std::vector<double> x = lattice(3);
  const std::vector<double> unit = x;
  lantern_particles p = interleaved(x);
  // The lattice scaled, and the spheres' radius (half its spacing) with it.
  const auto warning = [&](const std::string &name, double scale, const std::string &extra) {
    for (size_t i = 0; i < x.size(); ++i) x[i] = unit[i] * scale;
    char radius[64];
    std::snprintf(radius, sizeof radius, "    radius: %.17g\n", 0.5 * scale);
    EXPECT_EQ(open(scene_config(name, 96, 64, radius + extra)), LANTERN_OK) << message();
    EXPECT_EQ(lantern_publish(ctx_, &p), LANTERN_OK) << message();
    ::testing::internal::CaptureStderr();
    const lantern_status first = lantern_execute(ctx_, 0, 0.0);
    const lantern_status second = lantern_execute(ctx_, 1, 0.0);
    const std::string err = ::testing::internal::GetCapturedStderr();
    EXPECT_EQ(first, LANTERN_OK) << message();
    EXPECT_EQ(second, LANTERN_OK) << message();
    return err;
  };
  EXPECT_EQ(warning("plain", 1.0, ""), "");
  const std::string far = warning("far", 1e20, "");
  EXPECT_NE(far.find("beyond 1e18"), std::string::npos) << far;
  EXPECT_EQ(far.find("beyond 1e18"), far.rfind("beyond 1e18")) << "warned more than once: " << far;
  const std::string ao = "    ambient_occlusion: {method: screen}\n";
  EXPECT_EQ(warning("ao", 1.0, ao), "");
  const std::string tiny = warning("tiny", 1e-10, ao);
  EXPECT_NE(tiny.find("outside [1e-8, 1e10]: screen ambient occlusion"), std::string::npos) << tiny;
}

// A run killed while writing an image leaves a hidden temporary file; the next run's open removes
// it (only Lantern's temporary names, only files older than the run).
TEST_F(BadInput, OpenRemovesTemporaryFilesAKilledRunLeftInTheOutputFolder) {
  const std::string stale = (dir_ / ".k_0007.png.tmp99999999-0.png").string();
  const std::string mine = (dir_ / "k_0007.png").string();
  for (const std::string &path : {stale, mine}) {
    std::ofstream(path) << "half an image";
    const timespec old[2] = {{::time(nullptr) - 3600, 0}, {::time(nullptr) - 3600, 0}};
    ::utimensat(AT_FDCWD, path.c_str(), old, 0);
  }
  ASSERT_EQ(open(scene_config("k")), LANTERN_OK) << message();
  EXPECT_FALSE(std::filesystem::exists(stale));
  EXPECT_TRUE(std::filesystem::exists(mine));
}

}  // namespace
}  // namespace lantern::testing
