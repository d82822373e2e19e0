#include "core/common/quoted_text.h"

namespace lantern {
namespace {

void append_escaped(char c, std::string *out) {
  switch (c) {
    case '\n':
      *out += "\\n";
      return;
    case '\r':
      *out += "\\r";
      return;
    case '\t':
      *out += "\\t";
      return;
    case '\0':
      *out += "\\0";
      return;
    default:
      break;
  }
  const auto byte = static_cast<unsigned char>(c);
  if (byte >= 0x20 && byte <= 0x7e) {
    *out += c;
    return;
  }
  constexpr char kHex[] = "0123456789abcdef";
  *out += "\\x";
  *out += kHex[byte >> 4];
  *out += kHex[byte & 0xf];
}

}  // namespace

std::string quoted_text(std::string_view text, size_t limit) {
  const bool cut = text.size() > limit;
  std::string out = "'";
  for (const char c : text.substr(0, limit)) {
    // Quotes and backslashes are escaped only inside quotes, where they would be ambiguous.
    if (c == '\'' || c == '\\') out += '\\';
    append_escaped(c, &out);
  }
  out += cut ? "'..." : "'";
  return out;
}

std::string escaped_text(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) append_escaped(c, &out);
  return out;
}

std::string name_text(std::string_view name) {
  const bool plain = name.size() <= kQuotedTextLimit && escaped_text(name) == name;
  return plain ? std::string(name) : quoted_text(name);
}

}  // namespace lantern
