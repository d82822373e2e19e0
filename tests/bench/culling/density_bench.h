// lantern-bench --density: style: density at level-of-detail fractions 100/50/25/10/1 %, each
// z-order prefix (Rizzi et al. 2015, §3.5) next to a uniform random sample of the same size (a
// counter-based hash of the particle index), against the full density image: ms per frame,
// particles drawn, PSNR, SSIM, and PSNR after an 8x8 box filter (structure at a coarser scale).
// The transfer is asinh over a fixed range, the full image's auto range, so that every sample is
// mapped alike. Every scene runs twice: footprints of the scene's sphere radius r, and of 3 r
// (sigma = r: a smoothed density field rather than distinct particles). Also reports the splat's
// throughput (particles per second on one core) and the bytes it reads per particle.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "bench_scenes.h"
#include "error_plot.h"

namespace lantern::bench {

// The CSV header of density_bench.csv.
const char *density_csv_header();

// Runs every density mode on `scene` `runs` times (median); appends CSV rows and plot points;
// writes PNGs of the full, 10 % prefix and 10 % random images to `image_dir` when not empty.
// Returns false if an image could not be written.
bool run_density_bench(const BenchScene &scene, int runs, const std::string &image_dir,
                       std::ostream &csv, std::vector<PlotPoint> *plot);

}  // namespace lantern::bench
