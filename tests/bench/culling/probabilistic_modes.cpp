#include "probabilistic_modes.h"

#include <algorithm>
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
  // Ibrahim et al. 2022, §5.3 to the letter: converged only when no meshlet changed class (no 1%
  // tolerance) for `patience` iterations; Table 4 compares each strategy at its own convergence.
  ProbabilisticConfig strict;
  strict.quiet_share = 0.0;
  modes.push_back({"probabilistic@0.95+strict", strict});
  strict.random_acceptance = true;
  modes.push_back({"random50+strict", strict});
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
  // Table 4's quantity: the share of the meshlets (of the frustum's bricks) in class O.
  const int64_t all = st.meshlets[0] + st.meshlets[1] + st.meshlets[2] + st.meshlets[3];
  std::snprintf(text, sizeof text, ", O meshlets %.1f%%",
                100.0 * double(st.meshlets[3]) / double(std::max<int64_t>(all, 1)));
  note += text;
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
