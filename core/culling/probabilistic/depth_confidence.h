// Ibrahim et al.'s depth-confidence maps (§4): per pixel a representative depth d and a confidence
// C (the probability that a new sample in the pixel hits something no farther than d), kept twice -
// the cull buffer, which culling reads, and the accumulation buffer, which tries to build
// confidence for a nearer depth (algorithm 1) - and the confidence pyramid of eq. 23.
//
// The probabilities need the particle counts along the pixel's ray, D(d_a, d_b) (eq. 10): a
// RayDensity reads them from the cumulative histogram the density volume cast for that pixel
// (density_volume.h).
// Units: depths are view depths (ViewGeometry), counts are particles.
// Thread-safety: value types and pure functions; a pyramid is owned by one thread.
#pragma once

#include <cstdint>
#include <vector>

#include "core/view/view_geometry.h"

namespace lantern {

// D(t) of one pixel as a cumulative histogram: cum[i] particles nearer than z0 + i dz, i in
// [0, bins]; `scale` converts the cast ray's footprint to one pixel's.
struct RayDensity {
  const float *cum = nullptr;
  int bins = 0;
  double z0 = 0.0, dz = 1.0, scale = 1.0;

  // D(d_min, d): particles nearer than depth d (linear inside a bin).
  double closer(double d) const;
  // D(d_min, d_max).
  double total() const { return bins > 0 ? scale * cum[bins] : 0.0; }
  // B(d) = D(d, d_max) (eq. 11).
  double behind(double d) const { return total() - closer(d); }
};

// Eq. 21's sample budget N_budget: how many future samples a new depth may wait for to
// accumulate enough confidence. One iteration's passes times the convergence patience is the
// horizon over which a depth has to pay off; 32 is that for the defaults (4 passes x 3, rounded
// up to leave room for the occluder shuffle).
inline constexpr int kSampleBudget = 32;
// Eq. 20's clamp: at most this share of the nearer particles may be required as unique hits.
inline constexpr double kUniqueShareMax = 0.98;

// Eq. 8's update: the confidence after the k-th sample (k >= 1) of size alpha, for a depth with
// `nearer` particles in front of it (N of eq. 5; E(n(k-1)) unique particles hit so far).
double accumulate_confidence(double c, double alpha, uint32_t k, double nearer);

// OP(d, C) = B(d) C (eq. 12).
inline double occluded_particles(const RayDensity &ray, double d, double c) {
  return ray.behind(d) * c;
}

// Eqs. 13-22: the probability that a sample at depth d_s < d (size alpha) would, within
// kSampleBudget samples, reach a confidence that occludes more particles than (d, c) does.
double acceptance_probability(double d_s, double alpha, double d, double c, const RayDensity &ray);

// One pixel's two buffers (algorithm 1). Depths start at +inf (nothing known).
struct ConfidencePixel {
  float d, c;  // accumulation buffer
  float d_cull, c_cull;
  uint32_t k, k_cull;  // samples accumulated into each
  static ConfidencePixel empty();
};

// Algorithm 1's UpdateDepthAndConfidenceForSample for a sample at depth d_s of size alpha; `u`
// is the sample's uniform draw, read only when d_s < px->d (a caller may skip drawing it
// otherwise); `coin` replaces eq. 21 by a probability of 1/2 (the paper's random-acceptance
// baseline).
void update_pixel(ConfidencePixel *px, double d_s, double alpha, const RayDensity &ray, double u,
                  bool coin);

// The cull buffer as a pyramid (eq. 23): level 0 its (d_cull, c_cull); each next level the max
// depth and the mean confidence of its (up to) 2 x 2 children.
class ConfidencePyramid {
 public:
  void build(const std::vector<ConfidencePixel> &pixels, int width, int height);

  struct Verdict {
    bool failed = false;      // every texel over the rectangle is nearer than the depth
    double confidence = 0.0;  // mean confidence of those texels (0 for a box that passed)
  };
  // The depth test of a box with nearest depth `near` whose pixels are `rect` (clamped to the
  // image), at the finest level where the rectangle spans at most 8 x 8 texels (9 x 9 when it
  // straddles their boundaries): coarser texels would mix in depths from outside the box.
  Verdict test(const PixelRect &rect, double near) const;

 private:
  struct Level {
    int w = 0, h = 0;
    std::vector<float> d, c;
  };
  std::vector<Level> levels_;
};

}  // namespace lantern
