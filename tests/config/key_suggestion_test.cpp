#include "core/config/key_suggestion.h"

#include <gtest/gtest.h>

namespace lantern {
namespace {

TEST(KeySuggestion, EditDistance) {
  EXPECT_EQ(edit_distance("", ""), 0u);
  EXPECT_EQ(edit_distance("abc", ""), 3u);
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
  EXPECT_EQ(edit_distance("azimth", "azimuth"), 1u);
  EXPECT_EQ(edit_distance("Width", "width"), 0u);  // case-insensitive
}

TEST(KeySuggestion, NearestKey) {
  const std::vector<std::string> keys = {"azimuth", "elevation", "zoom", "fov"};
  EXPECT_EQ(nearest_key("azimth", keys), "azimuth");
  EXPECT_EQ(nearest_key("elevaton", keys), "elevation");
  EXPECT_EQ(nearest_key("zom", keys), "zoom");
  EXPECT_EQ(nearest_key("anything", {}), "");
}

TEST(KeySuggestion, TextNamesNearestAndAllKeys) {
  const std::string text = suggestion_text("widht", {"width", "height"});
  EXPECT_NE(text.find("did you mean 'width'?"), std::string::npos) << text;
  EXPECT_NE(text.find("height"), std::string::npos) << text;
}

}  // namespace
}  // namespace lantern
