// Reading a configuration file from disk, for lantern_open, lantern_reconfigure and `watch: true`.
//
// Only a regular file is read (a symbolic link is followed to one). A FIFO would block the
// reading rank in open() or read() until some writer appears, with the other ranks waiting for it
// in the next collective call; a character device such as /dev/zero or /dev/urandom never ends.
// The size is capped by the bytes actually read, not by what stat() says (0 for a device, and a
// file may grow while it is read). Thread-safe; never throws.
#pragma once

#include <cstdint>
#include <string>

namespace lantern {

// Configurations are a few kilobytes; the cap keeps memory and the broadcast of the text (an int
// count) far from any limit.
inline constexpr int64_t kMaxConfigBytes = int64_t(16) << 20;

// Reads `path` into *text. Returns "" on success, else why it cannot be a configuration, worded
// to follow the path in a message: "is a FIFO, not a regular file (a configuration is a YAML
// file)", "is larger than 16 MiB (...)", or the OS reason ("No such file or directory"). `kind`
// says in those brackets what the file should be (other small text inputs: colormap files).
std::string read_config_file(const std::string &path, std::string *text,
                             const char *kind = "a configuration is a YAML file");

}  // namespace lantern
