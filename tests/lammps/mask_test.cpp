// The group of lantern_particles (mask, mask_bits): particles outside it are skipped everywhere,
// so publishing everything with a mask gives the same image, dump and stats as publishing only
// the group's members - also when the group changes between steps (bricks refit) - and a mask
// without bits is an error naming mask_bits.
#include <cmath>
#include <fstream>
#include <memory>

#include <nlohmann/json.hpp>

#include "core/bricks/brick_set.h"
#include "core/dump/h5md_reader.h"
#include "tests/api/api_fixture.h"
#include "tests/support/image_file.h"

namespace lantern::testing {
namespace {

constexpr int32_t kGroupBit = 1 << 3;

// 1000 particles on a lattice; those outside the group sit far away with huge scalars, so a
// leak into the automatic camera (bounds) or the automatic colormap (scalar range) shows.
struct Particles {
  std::vector<double> x;
  std::vector<double> scalar;
  std::vector<int32_t> type, mask;
  std::vector<int64_t> id;

  static bool in_group(size_t i, int variant) {
    return (i + size_t(variant)) % 7 != 0 && i % 3 != 1;
  }

  static Particles make(int variant, double jitter = 0.0) {
    Particles p;
    for (int k = 0; k < 10; ++k)
      for (int j = 0; j < 10; ++j)
        for (int i = 0; i < 10; ++i) p.x.insert(p.x.end(), {double(i), double(j), double(k)});
    const size_t n = p.x.size() / 3;
    for (size_t i = 0; i < n; ++i) {
      const bool member = in_group(i, variant);
      p.mask.push_back(member ? (kGroupBit | 1) : (1 | 4));
      p.type.push_back(int32_t(i % 3));
      p.id.push_back(int64_t(i) + 1);
      p.scalar.push_back(member ? std::sin(0.1 * double(i)) : 1.0e6);
      p.x[3 * i] += jitter * std::cos(double(i));
      if (!member) p.x[3 * i + 2] += 100.0;
    }
    return p;
  }

  // The members only, copied: what the mask must be equivalent to.
  Particles members() const {
    Particles s;
    for (size_t i = 0; i < mask.size(); ++i) {
      if (!(mask[i] & kGroupBit)) continue;
      s.x.insert(s.x.end(), x.begin() + 3 * long(i), x.begin() + 3 * long(i) + 3);
      s.scalar.push_back(scalar[i]), s.type.push_back(type[i]), s.id.push_back(id[i]);
    }
    return s;
  }

  lantern_particles describe(bool with_mask) const {
    lantern_particles p{};
    p.count = int64_t(x.size() / 3);
    p.position = {x.data(), LANTERN_FLOAT64, 0};
    p.scalar = {scalar.data(), LANTERN_FLOAT64, 0};
    p.type = {type.data(), LANTERN_INT32, 0};
    p.id = {id.data(), LANTERN_INT64, 0};
    if (with_mask) {
      p.mask = {mask.data(), LANTERN_INT32, 0};
      p.mask_bits = kGroupBit;
    }
    return p;
  }
};

class Mask : public ApiTest {
 protected:
  // Two scenes (automatic camera and colormap; one by type through the CPU raster with hzb), a
  // dump and stats, all named after `tag`.
  std::string config(const std::string &tag) const {
    const std::string d = dir_.string() + "/";
    return "stats: '" + d + tag +
           ".jsonl'\n"
           "dump: {file: '" +
           d + tag +
           ".h5'}\n"
           "scenes:\n"
           "  - name: scalar\n    width: 160\n    height: 120\n    color: {by: scalar}\n"
           "    output: {pattern: '" +
           d + tag +
           "_scalar_{step:04d}.png'}\n"
           "  - name: type\n    width: 160\n    height: 120\n    renderer: cpu\n"
           "    culling: {occlusion: hzb}\n"
           "    output: {pattern: '" +
           d + tag + "_type_{step:04d}.png'}\n";
  }
  std::string file(const std::string &tag, const char *scene, int step) const {
    char buf[32];
    std::snprintf(buf, sizeof buf, "_%s_%04d.png", scene, step);
    return (dir_ / (tag + buf)).string();
  }
  void render(const std::string &tag, const Particles &p, bool with_mask, int step) {
    const lantern_particles d = p.describe(with_mask);
    ASSERT_EQ(lantern_publish(ctx_, &d), LANTERN_OK) << message();
    ASSERT_EQ(lantern_execute(ctx_, step, 0.0), LANTERN_OK) << message();
  }
  void expect_same_images(const std::string &a, const std::string &b, int step) {
    for (const char *scene : {"scalar", "type"}) {
      const auto fa = read_bytes(file(a, scene, step)), fb = read_bytes(file(b, scene, step));
      ASSERT_GT(fa.size(), 100u) << scene;
      EXPECT_EQ(fa, fb) << scene << " step " << step;
    }
  }
  int64_t finite_in_stats(const std::string &tag) const {
    std::ifstream in(dir_ / (tag + ".jsonl"));
    std::string line, last;
    while (std::getline(in, line)) last = line;
    return nlohmann::json::parse(last)["particles"]["finite"].get<int64_t>();
  }
  std::vector<double> dumped_positions(const std::string &tag, size_t frame) const {
    std::unique_ptr<H5mdReader> reader;
    EXPECT_TRUE(H5mdReader::open((dir_ / (tag + ".h5")).string(), MPI_COMM_WORLD, &reader).ok());
    if (!reader) return {};
    ParticleFrame f;
    const int64_t n = reader->frames().at(frame).count;
    EXPECT_TRUE(reader->read(frame, 0, n, &f).ok());
    return f.position;
  }
};

TEST_F(Mask, MaskedPublishEqualsPublishingTheMembersOnly) {
  const Particles all = Particles::make(0), members = all.members();
  ASSERT_LT(members.mask.size(), all.mask.size());
  ASSERT_EQ(open(config("masked")), LANTERN_OK) << message();
  render("masked", all, true, 0);
  ASSERT_EQ(open(config("members")), LANTERN_OK) << message();
  render("members", members, false, 0);
  lantern_close(ctx_);
  ctx_ = nullptr;
  expect_same_images("masked", "members", 0);
  EXPECT_EQ(finite_in_stats("masked"), int64_t(members.id.size()));
  const std::vector<double> masked = dumped_positions("masked", 0);
  EXPECT_EQ(masked.size(), members.x.size());
  EXPECT_EQ(masked, dumped_positions("members", 0));
}

TEST_F(Mask, GroupChangingBetweenStepsEqualsAFreshRenderOfTheNewMembers) {
  // One context over two steps (the second refits the first step's bricks), against a fresh
  // context for the second step's members.
  const Particles first = Particles::make(0), second = Particles::make(3, 0.05);
  ASSERT_EQ(open(config("masked")), LANTERN_OK) << message();
  render("masked", first, true, 0);
  render("masked", second, true, 1);
  ASSERT_EQ(open(config("members")), LANTERN_OK) << message();
  render("members", second.members(), false, 1);
  lantern_close(ctx_);
  ctx_ = nullptr;
  expect_same_images("masked", "members", 1);
}

TEST_F(Mask, Int64MaskWithHighBits) {
  Particles all = Particles::make(0);
  std::vector<int64_t> mask64(all.mask.size());
  constexpr int64_t kHigh = int64_t(1) << 40;
  for (size_t i = 0; i < mask64.size(); ++i) mask64[i] = (all.mask[i] & kGroupBit) ? kHigh : 1;
  ASSERT_EQ(open(config("masked")), LANTERN_OK) << message();
  lantern_particles d = all.describe(false);
  d.mask = {mask64.data(), LANTERN_INT64, 0};
  d.mask_bits = kHigh;
  ASSERT_EQ(lantern_publish(ctx_, &d), LANTERN_OK) << message();
  ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
  ASSERT_EQ(open(config("members")), LANTERN_OK) << message();
  render("members", all.members(), false, 0);
  lantern_close(ctx_);
  ctx_ = nullptr;
  expect_same_images("masked", "members", 0);
}

TEST_F(Mask, MaskWithoutBitsOrOfRealTypeIsAnArgumentError) {
  const Particles all = Particles::make(0);
  ASSERT_EQ(open(scene_config("bad")), LANTERN_OK) << message();
  lantern_particles d = all.describe(true);
  d.mask_bits = 0;
  EXPECT_EQ(lantern_publish(ctx_, &d), LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_NE(message().find("particles.mask_bits"), std::string::npos) << message();
  d = all.describe(true);
  d.mask.type = LANTERN_FLOAT32;
  EXPECT_EQ(lantern_publish(ctx_, &d), LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_NE(message().find("particles.mask.type"), std::string::npos) << message();
  // mask_bits without a mask is not read: every particle counts.
  d = all.describe(false);
  d.mask_bits = 0x10;
  EXPECT_EQ(lantern_publish(ctx_, &d), LANTERN_OK) << message();
}

TEST(MaskBricks, BricksHoldExactlyTheMembers) {
  const Particles all = Particles::make(0);
  ParticleDescription d{};
  d.count = int64_t(all.mask.size());
  d.position = {all.x.data(), DataType::kFloat64, 0};
  d.mask = {all.mask.data(), DataType::kInt32, 0};
  d.mask_bits = kGroupBit;
  ParticleArrays p;
  ASSERT_TRUE(ParticleArrays::validate(d, &p).ok());
  const BrickSet set = build_bricks(p, BrickOptions{});
  ASSERT_EQ(set.particle_count(), int64_t(all.members().id.size()));
  for (const uint32_t i : set.order) EXPECT_TRUE(all.mask[i] & kGroupBit) << i;
  EXPECT_EQ(set.nonfinite, 0);
  EXPECT_LT(set.hi.z, 50.0);  // the far-away non-members are not in the bounds
}

}  // namespace
}  // namespace lantern::testing
