// Memory asked for by the configuration: the sum over scenes is checked at lantern_open and
// lantern_reconfigure (32 scenes that each pass the per-scene limit opened fine and would have
// needed 64 GiB per rank), and running out of memory while drawing is LANTERN_ERR_OUT_OF_MEMORY
// naming the scene and the size.
#include <sys/resource.h>

#include <fstream>
#include <string>

#include "tests/api/api_fixture.h"

namespace lantern::testing {
namespace {

using MemoryBudget = ApiTest;

// `n` scenes of 2048^2 at 64 samples: each at the per-scene limit (a 2 GiB sample frame).
std::string many_scenes(const std::filesystem::path &dir, int n) {
  std::string yaml = "scenes:\n";
  for (int i = 0; i < n; ++i)
    yaml += "  - name: big" + std::to_string(i) +
            "\n    width: 2048\n    height: 2048\n    samples: 64\n"
            "    output: {pattern: '" +
            (dir / "{scene}_{step}.png").string() + "'}\n";
  return yaml;
}

TEST_F(MemoryBudget, ScenesWhoseSumCannotFitAreRefusedAtOpenAndOnReconfigure) {
  // 64 scenes: about 260 GiB per rank by the estimate, more than any test machine's memory.
  ASSERT_EQ(open(many_scenes(dir_, 64)), LANTERN_ERR_OUT_OF_MEMORY);
  const std::string m = message();
  EXPECT_NE(m.find("the 64 scenes need about 260.0 GiB per rank"), std::string::npos) << m;
  EXPECT_NE(m.find("'big0' 4.1 GiB"), std::string::npos) << m;
  EXPECT_NE(m.find("on this node shared by 1 rank"), std::string::npos) << m;
  // One of them opens; the 64 as a reconfiguration are refused and the one scene stays.
  ASSERT_EQ(open(many_scenes(dir_, 1)), LANTERN_OK) << message();
  EXPECT_EQ(lantern_reconfigure(ctx_, many_scenes(dir_, 64).c_str()), LANTERN_ERR_OUT_OF_MEMORY);
  EXPECT_NE(message().find("260.0 GiB"), std::string::npos) << message();
}

// This process's lazily freed resident KiB (LazyFree of /proc/self/smaps_rollup); -1 where the
// system does not say.
long long lazily_freed_kib() {
  std::ifstream rollup("/proc/self/smaps_rollup");
  if (!rollup) return -1;
  for (std::string line; std::getline(rollup, line);)
    if (line.rfind("LazyFree:", 0) == 0) return std::stoll(line.substr(9));
  return -1;
}

// A step's scratch is kept lazily freed for the next step while the context is open (its pages
// are still resident), and handed back to the system when the context is closed.
TEST_F(MemoryBudget, ScratchKeptForTheNextStepGoesBackAtClose) {
  if (lazily_freed_kib() < 0) GTEST_SKIP() << "no LazyFree in /proc/self/smaps_rollup";
  lantern_close(ctx_);
  ctx_ = nullptr;  // and with it what earlier tests kept
  const long long before = lazily_freed_kib();
  ASSERT_EQ(open(scene_config("kept", 1024, 1024, "    renderer: cpu\n")), LANTERN_OK) << message();
  std::vector<double> x = lattice(24);
  const lantern_particles p = interleaved(x);
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
  // At least the CPU raster's depth pyramid over 1024 x 1024 pixels (about 1.3 MiB).
  const long long kept = lazily_freed_kib() - before;
  if (kept <= 0) GTEST_SKIP() << "the kernel took or never kept the lazily freed pages";
  EXPECT_GE(kept, 1024);
  EXPECT_EQ(lantern_close(ctx_), LANTERN_OK);
  ctx_ = nullptr;
  EXPECT_LT(lazily_freed_kib() - before, 256) << "pages still kept after lantern_close";
}

#if defined(__SANITIZE_ADDRESS__)
#define LANTERN_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define LANTERN_UNDER_ASAN 1
#endif
#endif

TEST_F(MemoryBudget, RunningOutWhileDrawingNamesTheSceneAndTheFrame) {
#ifdef LANTERN_UNDER_ASAN
  GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space: RLIMIT_AS cannot be "
                  "lowered under it";
#else
  ASSERT_EQ(open("gl: none\nscenes:\n  - name: huge\n    width: 2048\n    height: 2048\n"
                 "    samples: 16\n    renderer: cpu\n    output: {pattern: '" +
                 (dir_ / "huge_{step}.png").string() + "'}\n"),
            LANTERN_OK)
      << message();
  std::vector<double> x = lattice(4);
  const lantern_particles p = interleaved(x);
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  // Address space for 128 MiB more than this process holds: the 512 MiB frame cannot be made.
  std::ifstream statm("/proc/self/statm");
  long long pages = 0;
  statm >> pages;
  rlimit saved{};
  getrlimit(RLIMIT_AS, &saved);
  rlimit limited = saved;
  limited.rlim_cur = rlim_t(pages * sysconf(_SC_PAGESIZE) + (int64_t(128) << 20));
  ASSERT_EQ(setrlimit(RLIMIT_AS, &limited), 0);
  const lantern_status st = lantern_execute(ctx_, 0, 0.0);
  setrlimit(RLIMIT_AS, &saved);
  EXPECT_EQ(st, LANTERN_ERR_OUT_OF_MEMORY) << message();
  EXPECT_NE(message().find("scenes 'huge': out of memory drawing 8192 x 8192 pixels (536870912 "
                           "bytes for the frame on this rank)"),
            std::string::npos)
      << message();
#endif
}

}  // namespace
}  // namespace lantern::testing
