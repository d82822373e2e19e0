#include "core/config/file_pattern.h"

#include <cinttypes>
#include <cstdio>
#include <optional>

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

// Walks the pattern once. With `error` set, stops at the first problem and describes it there
// (kConfig); otherwise expands (copying malformed parts through).
std::string walk(const std::string &pattern, int64_t step, const std::string &scene,
                 Status *error) {
  std::string out;
  for (size_t i = 0; i < pattern.size(); ++i) {
    const char c = pattern[i];
    if ((c == '{' || c == '}') && i + 1 < pattern.size() && pattern[i + 1] == c) {
      out += c;
      ++i;
      continue;
    }
    if (c == '}') {
      if (error) {
        *error = {StatusCode::kConfig,
                  "unmatched '}' at position " + std::to_string(i) + " (write '}}' for a brace)"};
        return "";
      }
      out += c;
      continue;
    }
    if (c != '{') {
      out += c;
      continue;
    }
    const size_t close = pattern.find('}', i);
    if (close == std::string::npos) {
      if (error) {
        *error = {StatusCode::kConfig, "unclosed '{' at position " + std::to_string(i)};
        return "";
      }
      out += pattern.substr(i);
      break;
    }
    const std::string body = pattern.substr(i + 1, close - i - 1);
    const std::optional<Placeholder> placeholder = parse_placeholder(body);
    if (!placeholder) {
      if (error) {
        *error = {StatusCode::kConfig,
                  "unknown placeholder '{" + body +
                      "}'; allowed: {step}, {step:0Nd} (N = 1..20, e.g. {step:06d}), {scene}"};
        return "";
      }
      out += pattern.substr(i, close - i + 1);
    } else if (placeholder->kind == Placeholder::kScene) {
      out += scene;
    } else {
      out += format_step(step, placeholder->width);
    }
    i = close;
  }
  return out;
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
