// lantern-bench --opaque-lod: level of detail on opaque spheres (style: spheres) at fractions
// 100/50/25/10/1 %, each next to a uniform random sample of the same size drawn with the same
// radius rule (each grown as level of detail grows the spheres it keeps; sample_hash.h), against
// the full render. Every image - the no-LOD reference too - is drawn by the CPU raster with hzb
// occlusion culling, so the speed-up is LOD's own. Per mode: ms per frame (selection + raster + CPU
// splats), spheres ray-cast and points splatted, PSNR, SSIM and PSNR after an 8x8 box filter.
// `lod+points_X%` is lod with lod.point_path (spheres under half a pixel splatted on the CPU).
#pragma once

#include <ostream>
#include <vector>

#include "bench_scenes.h"
#include "error_plot.h"

namespace lantern::bench {

// The CSV header of opaque_lod_bench.csv.
const char *opaque_lod_csv_header();

// Runs every mode on `scene` `runs` times (median, modes interleaved run by run); prints a
// table and appends CSV rows and plot points.
void run_opaque_lod_bench(const BenchScene &scene, int runs, std::ostream &csv,
                          std::vector<PlotPoint> *plot);

}  // namespace lantern::bench
