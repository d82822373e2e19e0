// lantern-bench --samples 1,4,16: super-sampled anti-aliasing (scene key `samples`) on the CPU
// raster, brute force and hzb, against a 64-sample brute-force reference; and, with --pipeline,
// whole frames through Lantern's pipeline (Runtime: culling, drawing, compositing, distributed
// down-sampling, PNG) with the peak memory of the process, instead of the table (under mpiexec).
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "bench_scenes.h"
#include "error_plot.h"

namespace lantern::bench {

// One table for scene `bs`: for every N of `samples` and the modes brute_force and hzb, the median
// ms per frame of `runs` (cull + draw at sample resolution + down-sampling), culled %, the error
// against the 64-sample brute-force image (differing pixels, PSNR, SSIM), differing pixels
// against brute force at the same N, and the speed-up over brute force at N = 1. Appends rows to
// `csv` (header: supersampling_csv_header()) and points to `plot`.
void run_supersampling_scene(const BenchScene &bs, const std::vector<int> &samples, int runs,
                             std::ostream &csv, std::vector<PlotPoint> *plot);
const char *supersampling_csv_header();

// Whole frames of `bs` through the pipeline (lantern::Runtime on MPI_COMM_WORLD, occlusion hzb,
// renderer auto), for every N of `samples` in the order given: median ms per frame of `runs`
// steps after one warm-up, the ratio to the first N, the sample frame's bytes and the process's
// peak RSS (getrusage) after that N's frames. Images go to `out`.
void run_supersampling_pipeline(const BenchScene &bs, const std::vector<int> &samples, int runs,
                                const std::string &out);

}  // namespace lantern::bench
