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
    const Status s = acquire_renderer(GlBackend::kAuto, &session_, &renderer_);
    ASSERT_TRUE(s.ok()) << s.message;
  }

  std::shared_ptr<GlSession> session_;
  SphereRenderer *renderer_ = nullptr;
};

}  // namespace lantern::testing
