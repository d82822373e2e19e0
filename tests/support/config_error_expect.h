// Test support: loads a configuration document that must be refused and checks the error. Every
// configuration error names the key, its line and what is allowed, so tests pass the fragments
// they expect in the message: expect_config_error("scenes:\n  - widht: 3\n", {"'widht'", "line
// 2"}).
#pragma once

#include <gtest/gtest.h>

#include <initializer_list>
#include <string>

#include "core/config/config_loader.h"

namespace lantern::testing {

// Expects load_config(document) to fail with StatusCode::kConfig, its message to contain every
// fragment, and the output Config to be left untouched. Returns the message.
inline std::string expect_config_error(const std::string &document,
                                       std::initializer_list<const char *> fragments) {
  Config c;
  c.verbose = true;  // sentinel: a failed load must leave the output untouched
  const Status status = load_config(document, &c);
  const std::string &error = status.message;
  EXPECT_FALSE(status.ok()) << document;
  EXPECT_EQ(status.code, StatusCode::kConfig) << document << "\n" << error;
  for (const char *fragment : fragments)
    EXPECT_NE(error.find(fragment), std::string::npos)
        << "missing '" << fragment << "' in: " << error;
  EXPECT_TRUE(c.verbose);
  return error;
}

}  // namespace lantern::testing
