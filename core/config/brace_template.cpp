#include "core/config/brace_template.h"

namespace lantern {

std::string expand_braces(const std::string &text, const BraceField &field, Status *error) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if ((c == '{' || c == '}') && i + 1 < text.size() && text[i + 1] == c) {
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
    const size_t close = text.find('}', i + 1);
    if (close == std::string::npos) {
      if (error) {
        *error = {StatusCode::kConfig,
                  "unclosed '{' at position " + std::to_string(i) + " (write '{{' for a brace)"};
        return "";
      }
      out += text.substr(i);
      break;
    }
    const std::string body = text.substr(i + 1, close - i - 1);
    std::string why;
    const std::optional<std::string> expanded = field(body, &why);
    if (expanded) {
      out += *expanded;
    } else if (error) {
      *error = {StatusCode::kConfig, why};
      return "";
    } else {
      out += text.substr(i, close - i + 1);
    }
    i = close;
  }
  return out;
}

}  // namespace lantern
