#include "core/config/file_pattern.h"

#include <cinttypes>
#include <cstdio>
#include <optional>

#include "core/config/brace_template.h"

namespace lantern {

namespace {

constexpr int kMaxStepWidth = 20;  // int64 has at most 19 digits plus a sign

struct Placeholder {
  enum Kind { kStep, kScene } kind;
  int width;  // zero-padding width for kStep; 0 = none
};

// Parses the text between braces; nullopt if it is not a known placeholder.
std::optional<Placeholder> parse_placeholder(const std::string &body) {
  if (body == "scene") return Placeholder{Placeholder::kScene, 0};
  if (body == "step") return Placeholder{Placeholder::kStep, 0};
  const std::string prefix = "step:0";
  if (body.size() < prefix.size() + 2 || body.compare(0, prefix.size(), prefix) != 0 ||
      body.back() != 'd')
    return std::nullopt;
  const std::string digits = body.substr(prefix.size(), body.size() - prefix.size() - 1);
  if (digits.empty() || digits.size() > 2) return std::nullopt;
  int width = 0;
  for (const char c : digits) {
    if (c < '0' || c > '9') return std::nullopt;
    width = width * 10 + (c - '0');
  }
  if (width < 1 || width > kMaxStepWidth) return std::nullopt;
  return Placeholder{Placeholder::kStep, width};
}

std::string format_step(int64_t step, int width) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%0*" PRId64, width, step);
  return buffer;
}

std::string walk(const std::string &pattern, int64_t step, const std::string &scene,
                 Status *error) {
  const BraceField field = [&](const std::string &body,
                               std::string *why) -> std::optional<std::string> {
    const std::optional<Placeholder> placeholder = parse_placeholder(body);
    if (!placeholder) {
      *why = "unknown placeholder '{" + body +
             "}'; allowed: {step}, {step:0Nd} (N = 1..20, e.g. {step:06d}), {scene}";
      return std::nullopt;
    }
    if (placeholder->kind == Placeholder::kScene) return scene;
    return format_step(step, placeholder->width);
  };
  return expand_braces(pattern, field, error);
}

}  // namespace

Status validate_pattern(const std::string &pattern) {
  if (pattern.empty()) return {StatusCode::kConfig, "the pattern is empty"};
  Status error;
  walk(pattern, 0, "", &error);
  return error;
}

std::string expand_pattern(const std::string &pattern, int64_t step, const std::string &scene) {
  return walk(pattern, step, scene, nullptr);
}

bool pattern_uses_scene(const std::string &pattern) {
  // Expanding with two different scene names differs exactly when {scene} is used.
  return expand_pattern(pattern, 0, "a") != expand_pattern(pattern, 0, "b");
}

}  // namespace lantern
