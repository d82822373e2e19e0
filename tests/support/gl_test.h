// Test support: a GoogleTest fixture with the process's GL session and sphere renderer.
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "core/render/gl_session.h"
#include "tests/support/status_expect.h"

namespace lantern::testing {

class GlTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_OK(GlSession::acquire(&session_));
    ASSERT_TRUE(session_);
    ASSERT_OK(session_->renderer(&renderer_));
    ASSERT_TRUE(renderer_);
  }

  std::shared_ptr<GlSession> session_;
  SphereRenderer *renderer_ = nullptr;
};

}  // namespace lantern::testing
