// Test support: GoogleTest checks that a lantern::Status is OK, printing its code and message
// when it is not. EXPECT_OK(load_config(text, &c)) << "more context";
#pragma once

#include <gtest/gtest.h>

#include "core/common/status.h"

namespace lantern::testing {

inline ::testing::AssertionResult IsOk(const Status &s) {
  if (s.ok()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "status " << static_cast<int>(s.code) << ": " << s.message;
}

}  // namespace lantern::testing

#define EXPECT_OK(expr) EXPECT_TRUE(::lantern::testing::IsOk(expr))
#define ASSERT_OK(expr) ASSERT_TRUE(::lantern::testing::IsOk(expr))
