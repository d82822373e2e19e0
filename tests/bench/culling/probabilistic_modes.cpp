#include "probabilistic_modes.h"

#include <cstdio>
#include <cstdlib>

namespace lantern::bench {

std::vector<ProbabilisticMode> probabilistic_modes() {
  std::vector<ProbabilisticMode> modes;
  for (const auto &[name, c] : {std::pair{"probabilistic@0.99", 0.99},
                                {"probabilistic@0.95", 0.95},
                                {"probabilistic@0.90", 0.90}}) {
    ProbabilisticConfig config;
    config.confidence = c;
    modes.push_back({name, config});
  }
  ProbabilisticConfig coin;  // C_occ 0.95, samples accepted by a fair coin
  coin.random_acceptance = true;
  modes.push_back({"random50", coin});
  return modes;
}

std::string probabilistic_note(const ProbabilisticStats &st, const Frame &image,
                               const Frame *exact) {
  char text[256];
  std::snprintf(text, sizeof text,
                " (iterations %lld, samples %lld, meshlets P/L/M/O %lld/%lld/%lld/%lld",
                static_cast<long long>(st.iterations), static_cast<long long>(st.samples),
                static_cast<long long>(st.meshlets[0]), static_cast<long long>(st.meshlets[1]),
                static_cast<long long>(st.meshlets[2]), static_cast<long long>(st.meshlets[3]));
  std::string note = text;
  if (exact && exact->pixel_count() == image.pixel_count()) {
    long long beyond = 0;
    for (size_t i = 0; i < image.pixel_count(); ++i)
      for (int ch = 0; ch < 3; ++ch)
        if (std::abs(int(image.rgba[4 * i + ch]) - int(exact->rgba[4 * i + ch])) > 2) {
          ++beyond;
          break;
        }
    std::snprintf(text, sizeof text, ", >2 levels vs exact CPU: %lld px = %.3f%%", beyond,
                  100.0 * double(beyond) / double(image.pixel_count()));
    note += text;
  }
  return note + ")";
}

}  // namespace lantern::bench
