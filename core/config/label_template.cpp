#include "core/config/label_template.h"

#include <cinttypes>
#include <cstdio>
#include <optional>

#include "core/config/brace_template.h"

namespace lantern {
namespace {

constexpr int kMaxWidth = 40;      // field width, characters
constexpr int kMaxPrecision = 17;  // digits after the point: a double has no more

// A field's format: printf's [0][width][.precision][type], checked against what the field takes.
struct Field {
  enum Kind { kStep, kTime, kScene } kind;
  bool zero = false;
  int width = 0;
  int precision = -1;  // -1: none
  char type = 0;       // d (step); f, e, g (time); 0: the field's default
};

// Reads digits from body[*i]; nullopt when there are none or too many.
std::optional<int> read_number(const std::string &body, size_t *i, int max) {
  int value = 0;
  const size_t start = *i;
  while (*i < body.size() && body[*i] >= '0' && body[*i] <= '9') {
    value = value * 10 + (body[*i] - '0');
    if (value > max) return std::nullopt;
    ++*i;
  }
  if (*i == start) return std::nullopt;
  return value;
}

// Parses the text between braces; on failure *why says what is wrong.
std::optional<Field> parse_field(const std::string &body, std::string *why) {
  const size_t colon = body.find(':');
  const std::string name = body.substr(0, colon);
  Field f{};
  if (name == "step") {
    f.kind = Field::kStep;
  } else if (name == "time") {
    f.kind = Field::kTime;
  } else if (name == "scene") {
    f.kind = Field::kScene;
  } else {
    *why = "unknown field {" + body + "} (the fields are {step}, {time} and {scene})";
    return std::nullopt;
  }
  if (colon == std::string::npos) return f;
  const std::string spec = body.substr(colon + 1);
  const std::string bad = "{" + body + "}: ";
  if (f.kind == Field::kScene) {
    *why = bad + "{scene} takes no format";
    return std::nullopt;
  }
  size_t i = 0;
  if (i < spec.size() && spec[i] == '0') {
    f.zero = true;
    ++i;
  }
  if (i < spec.size() && spec[i] >= '1' && spec[i] <= '9') {
    const std::optional<int> width = read_number(spec, &i, kMaxWidth);
    if (!width) {
      *why = bad + "the width is at most " + std::to_string(kMaxWidth);
      return std::nullopt;
    }
    f.width = *width;
  }
  if (i < spec.size() && spec[i] == '.') {
    ++i;
    const std::optional<int> precision = read_number(spec, &i, kMaxPrecision);
    if (!precision) {
      *why = bad + "'.' needs a precision of 0 to " + std::to_string(kMaxPrecision) + " digits";
      return std::nullopt;
    }
    f.precision = *precision;
  }
  if (i < spec.size()) f.type = spec[i++];
  if (i != spec.size() || (f.kind == Field::kStep && (f.type != 'd' || f.precision >= 0)) ||
      (f.kind == Field::kTime && f.type != 'f' && f.type != 'e' && f.type != 'g')) {
    *why = bad + (f.kind == Field::kStep ? "a step's format is like 06d or 8d"
                                         : "a time's format is like .2f, .3e, .4g or 8.2f");
    return std::nullopt;
  }
  return f;
}

std::string format_field(const Field &f, int64_t step, double time, const std::string &scene) {
  char buffer[128];
  switch (f.kind) {
    case Field::kScene:
      return scene;
    case Field::kStep:
      std::snprintf(buffer, sizeof buffer, f.zero ? "%0*" PRId64 : "%*" PRId64, f.width, step);
      return buffer;
    case Field::kTime:
      break;
  }
  const char type = f.type == 0 ? 'g' : f.type;
  const int precision = f.precision >= 0 ? f.precision : 6;  // printf's default
  const std::string format = std::string(f.zero ? "%0*.*" : "%*.*") + type;
  // 'f' of a large time has about log10|time| digits (309 for 1e308): sized by a first call,
  // where 128 bytes cut 1e200 to 127 digits of "1000...", read as 1e126.
  const int length = std::snprintf(buffer, sizeof buffer, format.c_str(), f.width, precision, time);
  if (length < int(sizeof buffer)) return buffer;
  std::string whole(size_t(length) + 1, '\0');
  std::snprintf(whole.data(), whole.size(), format.c_str(), f.width, precision, time);
  whole.resize(size_t(length));
  return whole;
}

std::string walk(const std::string &text, int64_t step, double time, const std::string &scene,
                 Status *error) {
  const BraceField field = [&](const std::string &body,
                               std::string *why) -> std::optional<std::string> {
    const std::optional<Field> f = parse_field(body, why);
    if (!f) return std::nullopt;
    return format_field(*f, step, time, scene);
  };
  return expand_braces(text, field, error);
}

}  // namespace

Status validate_label_template(const std::string &text) {
  Status error;
  walk(text, 0, 0.0, "", &error);
  return error;
}

std::string expand_label(const std::string &text, int64_t step, double time,
                         const std::string &scene) {
  return walk(text, step, time, scene, nullptr);
}

}  // namespace lantern
