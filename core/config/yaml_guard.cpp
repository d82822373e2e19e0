#include "core/config/yaml_guard.h"

#include <yaml-cpp/eventhandler.h>

#include <sstream>

namespace lantern {
namespace {

// Where each document starts; nothing else is kept.
class DocumentStarts : public YAML::EventHandler {
 public:
  void OnDocumentStart(const YAML::Mark &mark) override { start = mark; }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark &, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark &, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark &, const std::string &, YAML::anchor_t,
                const std::string &) override {}
  void OnSequenceStart(const YAML::Mark &, const std::string &, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark &, const std::string &, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
  YAML::Mark start = YAML::Mark::null_mark();
};

std::string where(const YAML::Mark &mark) {
  return "line " + std::to_string(mark.line + 1) + ", column " + std::to_string(mark.column + 1);
}

// YAML's limit on an implicit (unquoted or single-line quoted) key.
constexpr size_t kMaxImplicitKey = 1024;

// The first key longer than kMaxImplicitKey: a run of characters with no line break or flow
// indicator that ends in ':'. Its length and line, or {0, 0}.
std::pair<size_t, size_t> long_key(const std::string &text) {
  size_t line = 0, run = 0, run_line = 0;
  for (const char c : text) {
    if (c == ':' && run > kMaxImplicitKey) return {run, run_line};
    if (c == '\n' || c == ':' || c == ',' || c == '{' || c == '}' || c == '[' || c == ']') {
      run = 0;
    } else {
      if (run == 0) run_line = line;
      ++run;
    }
    if (c == '\n') ++line;
  }
  return {0, 0};
}

}  // namespace

std::string check_yaml_text(const std::string &text) {
  try {
    std::istringstream in(text);
    YAML::Parser parser(in);
    DocumentStarts starts;
    YAML::Mark previous = YAML::Mark::null_mark();
    // A document that starts where the last one started is the loop. (More than one document
    // is an error for the loader anyway; the cap only bounds this pass on long multi-document
    // text.)
    for (int document = 0; document < 1000 && parser.HandleNextDocument(starts); ++document) {
      if (document > 0 && starts.start.pos == previous.pos) {
        const size_t at = size_t(starts.start.pos);
        const char c = at < text.size() ? text[at] : ' ';
        return where(starts.start) + ": malformed YAML: '" + std::string(1, c) +
               "' where no flow collection ([...] or {...}) is open (a stray comma?)";
      }
      previous = starts.start;
    }
  } catch (...) {
    // A ParserException: the loader's own parse meets it again and reports it.
  }
  return {};
}

std::string explain_yaml_error(const std::string &text, const YAML::Mark &,
                               const std::string &message) {
  const bool about_a_key =
      message.find("map") != std::string::npos || message.find("flow") != std::string::npos;
  if (const auto [length, line] = long_key(text); about_a_key && length > 0)
    return "a key of " + std::to_string(length) + " characters at line " +
           std::to_string(line + 1) + " (YAML allows implicit keys of at most " +
           std::to_string(kMaxImplicitKey) + " characters; yaml-cpp says: " + message + ")";
  if (message == YAML::ErrorMsg::BAD_FILE)  // yaml-cpp's recursion limit, not a file problem
    return "nested too deeply (yaml-cpp stops at a few hundred levels of [..], {..} or "
           "indentation; a configuration nests a few)";
  return {};
}

}  // namespace lantern
