// libFuzzer: the YAML configuration loader (load_config_text) on any bytes, then what the
// pipeline derives from an accepted configuration at open (the memory estimate). Any crash,
// sanitizer report or uncaught exception is a bug: the loader must return a status.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/config/config_loader.h"
#include "core/pipeline/memory_budget.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const std::string text(reinterpret_cast<const char *>(data), size);
  lantern::Config config;
  const lantern::Status s = lantern::load_config_text(text, "fuzz", &config);
  if (s.ok()) {
    // An accepted configuration must be usable: every scene sized and named.
    for (const lantern::SceneMemory &m : lantern::estimate_scene_memory(config))
      if (m.bytes <= 0 || m.name.empty()) __builtin_trap();
  } else if (s.message.empty()) {
    __builtin_trap();  // every error names what is wrong
  }
  return 0;
}
