// Loads and validates the YAML configuration (the only place Lantern reads YAML).
//
// Thread-safe (no shared state); never throws. Every key is checked: an unknown key, a wrong
// type or an out-of-range value is an error naming the key, its line and its path.
#pragma once

#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/config/config.h"

namespace lantern {

// `path_or_document` is a YAML file path, or an inline YAML document when it contains a newline
// or starts with '{'. On success fills `*out` (defaults for every absent key) and returns OK; on
// failure returns kConfig (also for a file that cannot be read) with the error message and leaves
// `*out` untouched. `out` must not be null (kNullArgument).
Status load_config(const std::string &path_or_document, Config *out);

// The two halves of load_config, for a caller that needs the text itself (to compare it across
// ranks or with an earlier version: live configuration). read_config_text: the document, or the
// file's contents, into *text, and the file's path into *path ("" for an inline document);
// kConfig when the file cannot be read. load_config_text: parses and validates `text`; `source`
// names it in messages (a path, or "inline config").
Status read_config_text(const std::string &path_or_document, std::string *text, std::string *path);
Status load_config_text(const std::string &text, const std::string &source, Config *out);

// One section of the configuration's schema: its label as messages write it ("the top level",
// "scenes[]", "scenes[].camera") and its keys in the order messages list them.
struct ConfigSection {
  std::string label;
  std::vector<std::string> keys;
};

// Every section the loader reads, parents before children (for the documentation test and the
// "is a key of ..." hints). Thread-safe.
std::vector<ConfigSection> config_sections();

}  // namespace lantern
