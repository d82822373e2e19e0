// Test support: a GoogleTest fixture with the process's GL session and sphere renderer.
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "core/render/gl/gl_session.h"
#include "tests/support/status_expect.h"

namespace lantern::testing {

class GlTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!gl_backend_built(GlBackend::kEgl) && !gl_backend_built(GlBackend::kOsmesa))
      GTEST_SKIP() << "this Lantern is built without OpenGL (LANTERN_WITH_EGL/OSMESA=OFF)";
    ASSERT_OK(acquire_renderer(GlBackend::kAuto, &session_, &renderer_));
    ASSERT_TRUE(renderer_);
  }

  std::shared_ptr<GlSession> session_;
  SphereRenderer *renderer_ = nullptr;
};

}  // namespace lantern::testing
