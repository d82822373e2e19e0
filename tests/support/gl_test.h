// Test support: a GoogleTest fixture with the process's GL session and sphere renderer.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "core/render/gl_session.h"

namespace lantern::testing {

class GlTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string error;
    session_ = GlSession::acquire(&error);
    ASSERT_TRUE(session_) << error;
    renderer_ = session_->renderer(&error);
    ASSERT_TRUE(renderer_) << error;
  }

  std::shared_ptr<GlSession> session_;
  SphereRenderer *renderer_ = nullptr;
};

}  // namespace lantern::testing
