// Guards around yaml-cpp 0.7 (Debian 12) for text it mishandles, so that a configuration never
// hangs lantern_open (or a watched reload) and its errors say what is wrong.
//
//  - A ',' where no flow collection is open (a stray comma: ",", "[1],", "key: ,") makes
//    yaml-cpp's parser return an empty document without consuming the token, again and again:
//    YAML::LoadAll loops forever and its memory grows without bound. check_yaml_text runs
//    yaml-cpp's event parser first and stops as soon as a document starts where the last one
//    started.
//  - yaml-cpp reports nesting beyond its recursion limit as "bad file", and an implicit key longer
//    than YAML's 1024 characters as "end of map flow not found" or "illegal map value":
//    explain_yaml_error names the real cause.
// Thread-safe (no shared state); never throws.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>

namespace lantern {

// "" when yaml-cpp can load `text` without looping (it may still fail with an exception, which
// the loader reports), else "line L, column C: malformed YAML: ..." naming the stray token.
std::string check_yaml_text(const std::string &text);

// For a YAML::ParserException at `mark` with yaml-cpp's `message` on `text`: a clearer message
// (what to write after "malformed YAML: "), or "" when yaml-cpp's own is the best there is.
std::string explain_yaml_error(const std::string &text, const YAML::Mark &mark,
                               const std::string &message);

}  // namespace lantern
