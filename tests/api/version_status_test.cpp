// The version the library reports matches the header it was built from, and every status has
// a static name for logs. Neither needs a context or MPI.
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <utility>
#include <vector>

#include "lantern/lantern.h"

namespace lantern::testing {
namespace {

TEST(ApiVersion, RuntimeNumberIsTheHeaderVersion) {
  EXPECT_EQ(lantern_version_number(), LANTERN_VERSION);
  EXPECT_EQ(LANTERN_VERSION,
            LANTERN_VERSION_MAJOR * 10000 + LANTERN_VERSION_MINOR * 100 + LANTERN_VERSION_PATCH);
}

TEST(ApiVersion, StringIsTheDottedMacros) {
  ASSERT_NE(lantern_version(), nullptr);
  EXPECT_EQ(std::string(lantern_version()), std::to_string(LANTERN_VERSION_MAJOR) + "." +
                                                std::to_string(LANTERN_VERSION_MINOR) + "." +
                                                std::to_string(LANTERN_VERSION_PATCH));
}

// Every defined status, in order. A status appended to the enum must be added here: the
// "first undefined value" check below fails until it is.
const std::vector<std::pair<lantern_status, std::string>> &all_statuses() {
  static const std::vector<std::pair<lantern_status, std::string>> statuses = {
      {LANTERN_OK, "LANTERN_OK"},
      {LANTERN_ERR_NULL_ARGUMENT, "LANTERN_ERR_NULL_ARGUMENT"},
      {LANTERN_ERR_INVALID_ARGUMENT, "LANTERN_ERR_INVALID_ARGUMENT"},
      {LANTERN_ERR_CONFIG, "LANTERN_ERR_CONFIG"},
      {LANTERN_ERR_IO, "LANTERN_ERR_IO"},
      {LANTERN_ERR_GL, "LANTERN_ERR_GL"},
      {LANTERN_ERR_MPI, "LANTERN_ERR_MPI"},
      {LANTERN_ERR_OUT_OF_MEMORY, "LANTERN_ERR_OUT_OF_MEMORY"},
      {LANTERN_ERR_INTERNAL, "LANTERN_ERR_INTERNAL"},
  };
  return statuses;
}

TEST(ApiStatusString, EveryStatusHasADistinctStringThatNamesIt) {
  std::set<std::string> seen;
  for (size_t i = 0; i < all_statuses().size(); ++i) {
    const auto &[code, name] = all_statuses()[i];
    EXPECT_EQ(static_cast<size_t>(code), i) << name << ": the codes are 0, 1, 2, ...";
    const char *s = lantern_status_string(code);
    ASSERT_NE(s, nullptr) << name;
    const std::string text(s);
    EXPECT_EQ(text.rfind(name + ": ", 0), 0u) << "'" << text << "' does not start with " << name;
    EXPECT_GT(text.size(), name.size() + 2) << name << " has no description";
    EXPECT_TRUE(seen.insert(text).second) << "'" << text << "' is repeated";
    EXPECT_EQ(lantern_status_string(code), s) << name << ": not one static string";
  }
}

TEST(ApiStatusString, UndefinedValuesGiveTheUnknownString) {
  // Values in the enum's range that name no status (C callers may pass any int; that is
  // checked from C in c_api_test.c).
  const int first_undefined = static_cast<int>(all_statuses().size());
  for (int v : {first_undefined, first_undefined + 1, 15}) {
    const char *s = lantern_status_string(static_cast<lantern_status>(v));
    ASSERT_NE(s, nullptr) << v;
    EXPECT_STREQ(s, "unknown lantern_status") << v;
  }
}

}  // namespace
}  // namespace lantern::testing
