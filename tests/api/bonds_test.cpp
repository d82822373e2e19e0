// Bonds through the C API (lantern_publish_bonds): every bad input returns its status with a
// message naming the bond and index while the particles keep rendering; a bond gone bad after it
// was published is left out, reported on execute, and the rest drawn; publishing particles
// forgets the bonds; the stats count half-bonds.
#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/api/api_fixture.h"
#include "tests/support/image_file.h"

namespace lantern::testing {
namespace {

class Bonds : public ApiTest {
 protected:
  // A chain of 6 atoms along x (types 0, 1, 0, ...), bonds (i, i + 1) as LAMMPS's bondlist holds
  // them: int rows of (first, second, type).
  void SetUp() override {
    ApiTest::SetUp();
    for (int i = 0; i < 6; ++i) {
      x.insert(x.end(), {1.0 * i, 0.0, 0.0});
      type.push_back(i % 2);
      id.push_back(100 + i);
    }
    for (int i = 0; i + 1 < 6; ++i) list.insert(list.end(), {i, i + 1, i % 3});
  }

  std::string config(const std::string &name, const std::string &bonds = "    bonds: {}\n") {
    return scene_config(name, 160, 64,
                        "    radius: 0.2\n    background: [0, 0, 0]\n    renderer: cpu\n"
                        "    camera: {projection: orthographic, position: [2.5, 0, 20], "
                        "look_at: [2.5, 0, 0], up: [0, 1, 0]}\n" +
                            bonds);
  }
  lantern_particles particles() {
    lantern_particles p = interleaved(x);
    p.type = {type.data(), LANTERN_INT32, 0};
    p.id = {id.data(), LANTERN_INT64, 0};
    return p;
  }
  lantern_bonds bonds() {
    lantern_bonds b{};
    b.count = int64_t(list.size() / 3);
    b.first = {&list[0], LANTERN_INT32, 12};
    b.second = {&list[1], LANTERN_INT32, 12};
    b.type = {&list[2], LANTERN_INT32, 12};
    return b;
  }
  // Pixels of the image at `step` that are not the (black) background.
  int64_t lit_pixels(const std::string &name, int step) {
    const ImagePixels im = read_image(png(name, step));
    EXPECT_TRUE(im.error.empty()) << im.error;
    int64_t n = 0;
    for (size_t i = 0; i + 2 < im.pixels.size(); i += size_t(im.channels))
      n += (im.pixels[i] | im.pixels[i + 1] | im.pixels[i + 2]) != 0;
    return n;
  }
  nlohmann::json last_stats() {
    std::ifstream in(dir_ / "stats.jsonl");
    std::string line, last;
    while (std::getline(in, line)) last = line;
    return nlohmann::json::parse(last);
  }

  std::vector<double> x;
  std::vector<int32_t> type;
  std::vector<int64_t> id;
  std::vector<int32_t> list;
};

TEST_F(Bonds, BadBondsNameTheBondAndTheParticlesStillRender) {
  ASSERT_EQ(open(config("b")), LANTERN_OK) << message();
  const lantern_particles p = particles();
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK) << message();
  ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
  const int64_t atoms_only = [&] {
    lantern_bonds none{};
    EXPECT_EQ(lantern_publish_bonds(ctx_, &none), LANTERN_OK);
    EXPECT_EQ(lantern_execute(ctx_, 1, 0.0), LANTERN_OK);
    return lit_pixels("b", 1);
  }();
  const lantern_bonds good = bonds();
  ASSERT_EQ(lantern_publish_bonds(ctx_, &good), LANTERN_OK) << message();
  ASSERT_EQ(lantern_execute(ctx_, 2, 0.0), LANTERN_OK) << message();
  const int64_t with_bonds = lit_pixels("b", 2);
  EXPECT_GT(with_bonds, atoms_only + 100);  // the bonds fill the gaps between the atoms

  struct Case {
    const char *what;
    std::vector<int32_t> list;  // rows of (first, second, type)
    int64_t ghosts;
    std::vector<const char *> names;
  };
  const std::vector<Case> cases = {
      {"index beyond count + ghost_count",
       {0, 1, 0, 1, 6, 0},
       0,
       {"bonds.second[1]", "6", "count + ghost_count (6 + 0)"}},
      {"negative index", {0, 1, 0, 1, 2, 0, -3, 4, 0}, 0, {"bonds.first[2]", "-3", "negative"}},
      {"bond to itself", {0, 1, 0, 3, 3, 0}, 0, {"bonds[1]", "atom 3 (id 103)", "itself"}},
      {"two ghosts", {0, 1, 0, 6, 7, 0}, 2, {"bonds[1]", "both atoms are ghosts", "id 106"}},
      // count + ghost_count overflowed int64 and passed the 2^32 check.
      {"ghost count near INT64_MAX",
       {0, 1, 0},
       std::numeric_limits<int64_t>::max(),
       {"bonds.ghost_count", "is not below 2^32"}},
  };
  id.push_back(106), id.push_back(107);  // ghost ids for the ghost case
  x.insert(x.end(), {6, 0, 0, 7, 0, 0});
  type.insert(type.end(), {0, 1});
  for (const Case &c : cases) {
    std::vector<int32_t> rows = c.list;
    lantern_bonds b{};
    b.count = int64_t(rows.size() / 3);
    b.first = {&rows[0], LANTERN_INT32, 12};
    b.second = {&rows[1], LANTERN_INT32, 12};
    b.ghost_count = c.ghosts;
    const lantern_particles pub = particles();
    lantern_particles owned = pub;
    owned.count = 6;
    ASSERT_EQ(lantern_publish(ctx_, &owned), LANTERN_OK);
    EXPECT_EQ(lantern_publish_bonds(ctx_, &b), LANTERN_ERR_INVALID_ARGUMENT) << c.what;
    for (const char *name : c.names)
      EXPECT_NE(message().find(name), std::string::npos) << c.what << ": " << message();
    // Nothing else stops: the particles render, without bonds.
    ASSERT_EQ(lantern_execute(ctx_, 3, 0.0), LANTERN_OK) << c.what << ": " << message();
    EXPECT_EQ(lit_pixels("b", 3), atoms_only) << c.what;
  }

  // A NaN end, a ghost count without ids, a listing that is none, a missing index array, float
  // indices.
  x[3 * 4] = std::numeric_limits<double>::quiet_NaN();
  lantern_particles nan_p = particles();
  nan_p.count = 6;
  ASSERT_EQ(lantern_publish(ctx_, &nan_p), LANTERN_OK);
  EXPECT_EQ(lantern_publish_bonds(ctx_, &good), LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_NE(message().find("bonds[3]: atom 4 (id 104) (bonds.second) is at (nan"),
            std::string::npos)
      << message();
  x[3 * 4] = 4.0;
  lantern_particles no_ids = particles();
  no_ids.count = 6;
  no_ids.id = {};
  ASSERT_EQ(lantern_publish(ctx_, &no_ids), LANTERN_OK);
  lantern_bonds ghosts = good;
  ghosts.ghost_count = 2;
  EXPECT_EQ(lantern_publish_bonds(ctx_, &ghosts), LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_NE(message().find("bonds.ghost_count: 2 ghosts but no particle ids"), std::string::npos)
      << message();
  const lantern_particles pub = particles();
  lantern_particles owned = pub;
  owned.count = 6;
  ASSERT_EQ(lantern_publish(ctx_, &owned), LANTERN_OK);
  lantern_bonds bad_listing = good;
  const int seven = 7;
  std::memcpy(&bad_listing.listing, &seven, sizeof seven);
  EXPECT_EQ(lantern_publish_bonds(ctx_, &bad_listing), LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_NE(message().find("bonds.listing: 7"), std::string::npos) << message();
  lantern_bonds no_second = good;
  no_second.second = {};
  EXPECT_EQ(lantern_publish_bonds(ctx_, &no_second), LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_NE(message().find("bonds.second: NULL"), std::string::npos) << message();
  const float float_index[5] = {0, 1, 2, 3, 4};
  lantern_bonds floats = good;
  floats.first = {float_index, LANTERN_FLOAT32, 0};
  EXPECT_EQ(lantern_publish_bonds(ctx_, &floats), LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_NE(message().find("bonds.first.type"), std::string::npos) << message();
  EXPECT_EQ(lantern_publish_bonds(ctx_, nullptr), LANTERN_ERR_NULL_ARGUMENT);
  EXPECT_EQ(lantern_publish_bonds(nullptr, &good), LANTERN_ERR_NULL_ARGUMENT);
  // And the context is fine: the good bonds draw as before.
  ASSERT_EQ(lantern_publish_bonds(ctx_, &good), LANTERN_OK) << message();
  ASSERT_EQ(lantern_execute(ctx_, 4, 0.0), LANTERN_OK) << message();
  EXPECT_EQ(lit_pixels("b", 4), with_bonds);
}

TEST_F(Bonds, ABondGoneBadAfterPublishingIsLeftOutAndReportedAndTheRestDrawn) {
  ASSERT_EQ(open(config("late")), LANTERN_OK) << message();
  const lantern_particles p = particles();
  const lantern_bonds b = bonds();
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  ASSERT_EQ(lantern_publish_bonds(ctx_, &b), LANTERN_OK) << message();
  ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
  // The host rewrites its list in place: bond 2 now points past the particles.
  list[3 * 2 + 1] = 40;
  EXPECT_EQ(lantern_execute(ctx_, 1, 0.0), LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_NE(message().find("bonds.second[2]: 40 is not below count + ghost_count (6 + 0)"),
            std::string::npos)
      << message();
  // The image was still written: the atoms and the four good bonds.
  const int64_t all = lit_pixels("late", 0), without_one = lit_pixels("late", 1);
  EXPECT_LT(without_one, all);
  EXPECT_GT(without_one, all * 3 / 4);
  EXPECT_EQ(last_stats()["status"], int(LANTERN_ERR_INVALID_ARGUMENT));
  EXPECT_EQ(last_stats()["scenes"][0]["bonds"]["halves"], 8);
  // Repaired, the next step is whole again.
  list[3 * 2 + 1] = 3;
  ASSERT_EQ(lantern_execute(ctx_, 2, 0.0), LANTERN_OK) << message();
  EXPECT_EQ(lit_pixels("late", 2), all);
}

TEST_F(Bonds, PublishingParticlesForgetsTheBonds) {
  ASSERT_EQ(open(config("forget")), LANTERN_OK) << message();
  const lantern_particles p = particles();
  const lantern_bonds b = bonds();
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK);
  ASSERT_EQ(lantern_publish_bonds(ctx_, &b), LANTERN_OK);
  ASSERT_EQ(lantern_execute(ctx_, 1, 0.0), LANTERN_OK);
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  ASSERT_EQ(lantern_execute(ctx_, 2, 0.0), LANTERN_OK);
  EXPECT_GT(lit_pixels("forget", 1), lit_pixels("forget", 0));
  EXPECT_EQ(read_bytes(png("forget", 2)), read_bytes(png("forget", 0)));
}

// A bonds: section with no bonds ever published draws none, and says so once; a step that
// publishes zero bonds is not warned about.
TEST_F(Bonds, NoBondsPublishedIsWarnedOnce) {
  ASSERT_EQ(open(config("none")), LANTERN_OK) << message();
  const lantern_particles p = particles();
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  ::testing::internal::CaptureStderr();
  ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
  ASSERT_EQ(lantern_execute(ctx_, 1, 0.0), LANTERN_OK) << message();
  const std::string err = ::testing::internal::GetCapturedStderr();
  const std::string warning = "no rank published bonds (lantern_publish_bonds";
  ASSERT_NE(err.find(warning), std::string::npos) << err;
  EXPECT_EQ(err.find(warning, err.find(warning) + 1), std::string::npos) << "warned twice: " << err;
  ASSERT_EQ(open(config("zero")), LANTERN_OK) << message();
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  lantern_bonds none{};
  ASSERT_EQ(lantern_publish_bonds(ctx_, &none), LANTERN_OK) << message();
  ::testing::internal::CaptureStderr();
  ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
  EXPECT_EQ(::testing::internal::GetCapturedStderr().find(warning), std::string::npos);
}

TEST_F(Bonds, WithoutTheSectionBondsChangeNoByteAndCostNothing) {
  ASSERT_EQ(open(config("off", "")), LANTERN_OK) << message();
  const lantern_particles p = particles();
  const lantern_bonds b = bonds();
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK);
  ASSERT_EQ(lantern_publish_bonds(ctx_, &b), LANTERN_OK);
  ASSERT_EQ(lantern_execute(ctx_, 1, 0.0), LANTERN_OK);
  EXPECT_EQ(read_bytes(png("off", 1)), read_bytes(png("off", 0)));
  EXPECT_FALSE(last_stats()["scenes"][0].contains("bonds"));
}

TEST_F(Bonds, ColorByTypeNeedsBondTypesAndStatsCountHalves) {
  ASSERT_EQ(open(config("types", "    bonds: {color: by_type}\n")), LANTERN_OK) << message();
  const lantern_particles p = particles();
  lantern_bonds b = bonds();
  b.type = {};
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  ASSERT_EQ(lantern_publish_bonds(ctx_, &b), LANTERN_OK);
  EXPECT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_NE(message().find("scenes 'types': bonds.color is by_type but no bond type array"),
            std::string::npos)
      << message();
  b = bonds();
  ASSERT_EQ(lantern_publish_bonds(ctx_, &b), LANTERN_OK);
  ASSERT_EQ(lantern_execute(ctx_, 1, 0.0), LANTERN_OK) << message();
  const nlohmann::json s = last_stats()["scenes"][0]["bonds"];
  EXPECT_EQ(s["halves"], 10);
  EXPECT_EQ(s["drawn"], 10);
  EXPECT_EQ(s["occlusion_culled"], 0);
}

// Places the chain off the zero planes (a bound of exactly zero makes the half-bonds rebuild
// rather than refit), each atom nudged by `d` along x.
void place_chain(std::vector<double> *x, double d) {
  for (size_t i = 0; i < x->size() / 3; ++i) {
    (*x)[3 * i] = double(i) + 0.25 + d * std::sin(double(i));
    (*x)[3 * i + 1] = 0.25, (*x)[3 * i + 2] = 0.125;
  }
}

TEST_F(Bonds, AListRewrittenInPlaceIsDrawnAsAFreshContextDrawsIt) {
  ASSERT_EQ(open(config("inplace")), LANTERN_OK) << message();
  const lantern_particles p = particles();
  const lantern_bonds b = bonds();
  place_chain(&x, 0.0);
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  ASSERT_EQ(lantern_publish_bonds(ctx_, &b), LANTERN_OK) << message();
  ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
  // The atoms moved a little, the list is the same: the grouping is kept.
  place_chain(&x, 0.01);
  ASSERT_EQ(lantern_execute(ctx_, 1, 0.0), LANTERN_OK) << message();
  EXPECT_EQ(last_stats()["scenes"][0]["bonds"]["grouping_reused"], 1);
  // The host rewrites its list in place, as LAMMPS does when it re-neighbours: same address and
  // count, bond 4 is (0, 2) instead of (4, 5).
  list[3 * 4] = 0, list[3 * 4 + 1] = 2;
  place_chain(&x, 0.02);
  ASSERT_EQ(lantern_execute(ctx_, 2, 0.0), LANTERN_OK) << message();
  EXPECT_EQ(last_stats()["scenes"][0]["bonds"]["grouping_reused"], 0);
  // Bond (0, 2) lies over (0, 1) and (1, 2): the gap between atoms 4 and 5 shows.
  EXPECT_LT(lit_pixels("inplace", 2), lit_pixels("inplace", 1));
  lantern_context *fresh = nullptr;
  ASSERT_EQ(lantern_open(config("fresh").c_str(), LANTERN_COMM_WORLD, &fresh), LANTERN_OK);
  ASSERT_EQ(lantern_publish(fresh, &p), LANTERN_OK);
  ASSERT_EQ(lantern_publish_bonds(fresh, &b), LANTERN_OK);
  ASSERT_EQ(lantern_execute(fresh, 2, 0.0), LANTERN_OK) << lantern_error_message(fresh);
  lantern_close(fresh);
  EXPECT_EQ(read_bytes(png("inplace", 2)), read_bytes(png("fresh", 2)));
}

TEST_F(Bonds, KeepingTheGroupingGivesTheBytesOfBuildingItAsAtomsMove) {
  // A 12 x 12 x 3 network (bonds to the +x, +y and +z neighbours) seen at an angle: many bricks,
  // halves hidden by others. Off the zero planes, so that no bound is exactly zero.
  const int n = 12, layers = 3;
  std::vector<double> pos, rest;
  std::vector<int32_t> pairs;
  const auto at = [n](int i, int j, int k) { return (k * n + j) * n + i; };
  for (int k = 0; k < layers; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        rest.insert(rest.end(), {i + 0.3, j + 0.3, k + 0.3});
        if (i + 1 < n) pairs.insert(pairs.end(), {at(i, j, k), at(i + 1, j, k), 0});
        if (j + 1 < n) pairs.insert(pairs.end(), {at(i, j, k), at(i, j + 1, k), 1});
        if (k + 1 < layers) pairs.insert(pairs.end(), {at(i, j, k), at(i, j, k + 1), 2});
      }
  pos = rest;
  const std::string scene =
      "    radius: 0.2\n    background: [0, 0, 0]\n    renderer: cpu\n"
      "    camera: {position: [-4, -6, 14], look_at: [6, 6, 1], up: [0, 0, 1]}\n"
      "    bonds: {radius: 0.1, color: by_atom}\n";
  const std::string keep_config = scene_config("keep", 128, 96, scene);
  std::string build_config = scene_config("build", 128, 96, scene);
  build_config.replace(build_config.find("stats.jsonl"), 11, "stats_build.jsonl");
  lantern_particles p = interleaved(pos);
  lantern_bonds b{};
  b.count = int64_t(pairs.size() / 3);
  b.first = {&pairs[0], LANTERN_INT32, 12};
  b.second = {&pairs[1], LANTERN_INT32, 12};
  b.type = {&pairs[2], LANTERN_INT32, 12};
  ASSERT_EQ(open(keep_config), LANTERN_OK) << message();
  const int steps = 6;
  for (int step = 0; step < steps; ++step) {
    for (size_t c = 0; c < pos.size(); ++c)
      pos[c] = rest[c] + 0.04 * std::sin(0.7 * double(c) + double(step));
    // Published every step, as a host does: the bricks refit and the grouping is kept.
    ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK) << message();
    ASSERT_EQ(lantern_publish_bonds(ctx_, &b), LANTERN_OK) << message();
    ASSERT_EQ(lantern_execute(ctx_, step, 0.0), LANTERN_OK) << message();
    EXPECT_EQ(last_stats()["scenes"][0]["bonds"]["grouping_reused"], step > 0 ? 1 : 0) << step;
    // A fresh context builds everything for this step alone.
    lantern_context *fresh = nullptr;
    ASSERT_EQ(lantern_open(build_config.c_str(), LANTERN_COMM_WORLD, &fresh), LANTERN_OK);
    ASSERT_EQ(lantern_publish(fresh, &p), LANTERN_OK);
    ASSERT_EQ(lantern_publish_bonds(fresh, &b), LANTERN_OK);
    ASSERT_EQ(lantern_execute(fresh, step, 0.0), LANTERN_OK) << lantern_error_message(fresh);
    lantern_close(fresh);
    EXPECT_EQ(read_bytes(png("keep", step)), read_bytes(png("build", step))) << step;
  }
  EXPECT_NE(read_bytes(png("keep", 0)), read_bytes(png("keep", steps - 1)));
}

}  // namespace
}  // namespace lantern::testing
