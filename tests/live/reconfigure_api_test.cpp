// lantern_reconfigure through the C API: argument checks, a change that shows in the next image,
// and an error that names the key and keeps the running configuration.
#include <vector>

#include "tests/api/api_fixture.h"
#include "tests/support/image_file.h"

namespace lantern::testing {
namespace {

using Reconfigure = ApiTest;

TEST_F(Reconfigure, RejectsNullAndUnopenedContexts) {
  EXPECT_EQ(lantern_reconfigure(nullptr, "scenes: [{}]\n"), LANTERN_ERR_NULL_ARGUMENT);
  ASSERT_NE(open("scenes: [\n"), LANTERN_OK);  // an error-only context
  EXPECT_EQ(lantern_reconfigure(ctx_, scene_config("a").c_str()), LANTERN_ERR_INVALID_ARGUMENT);
  ASSERT_EQ(open(scene_config("a")), LANTERN_OK) << message();
  EXPECT_EQ(lantern_reconfigure(ctx_, nullptr), LANTERN_ERR_NULL_ARGUMENT);
  EXPECT_NE(message().find("config"), std::string::npos);
}

TEST_F(Reconfigure, NextImageChangesAndAnErrorKeepsTheConfiguration) {
  ASSERT_EQ(open(scene_config("a", 64, 48)), LANTERN_OK) << message();
  std::vector<double> x = lattice(8);
  const lantern_particles p = interleaved(x);
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
  const std::vector<char> original = read_bytes(png("a", 0));
  ASSERT_EQ(lantern_reconfigure(
                ctx_, scene_config("a", 64, 48, "    background: [0.2, 0.3, 0.4]\n").c_str()),
            LANTERN_OK)
      << message();
  ASSERT_EQ(lantern_execute(ctx_, 1, 0.0), LANTERN_OK) << message();
  const std::vector<char> changed = read_bytes(png("a", 1));
  EXPECT_NE(changed, original);
  EXPECT_EQ(read_bytes(png("a", 0)), original);
  EXPECT_EQ(lantern_reconfigure(ctx_, scene_config("a", 64, 48, "    radiuss: 1\n").c_str()),
            LANTERN_ERR_CONFIG);
  EXPECT_NE(message().find("radiuss"), std::string::npos) << message();
  ASSERT_EQ(lantern_execute(ctx_, 2, 0.0), LANTERN_OK) << message();
  EXPECT_EQ(read_bytes(png("a", 2)), changed);
}

}  // namespace
}  // namespace lantern::testing
