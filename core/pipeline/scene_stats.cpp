#include "core/pipeline/scene_stats.h"

#include <cstdio>

namespace lantern {
namespace {

std::string spread_text(const char *what, const RankSpread &s, const char *format) {
  char lo[32], hi[32], line[160];
  std::snprintf(lo, sizeof lo, format, s.min);
  std::snprintf(hi, sizeof hi, format, s.max);
  std::snprintf(line, sizeof line, "%s %s..%s (imbalance %.2f, max on rank %d)", what, lo, hi,
                s.imbalance(), s.max_rank);
  return line;
}

}  // namespace

void sum_counts_over_ranks(MPI_Comm comm, const CullStats &local, SceneStats *stats) {
  int64_t in[6] = {local.drawn,      local.splatted,    local.frustum_culled,
                   local.cut_culled, local.lod_dropped, local.occlusion_culled};
  int64_t out[6] = {0, 0, 0, 0, 0, 0};
  MPI_Allreduce(in, out, 6, MPI_INT64_T, MPI_SUM, comm);
  stats->drawn = out[0];
  stats->splatted = out[1];
  stats->frustum_culled = out[2];
  stats->cut_culled = out[3];
  stats->lod_dropped = out[4];
  stats->occlusion_culled = out[5];
}

void sum_bond_counts_over_ranks(MPI_Comm comm, const BondCounts &local, SceneStats *stats) {
  int64_t in[7] = {local.halves,         local.frustum_culled,   local.cut_culled,
                   local.lod_dropped,    local.occlusion_culled, local.drawn,
                   local.grouping_reused};
  int64_t out[7] = {0, 0, 0, 0, 0, 0, 0};
  MPI_Allreduce(in, out, 7, MPI_INT64_T, MPI_SUM, comm);
  BondCounts c;
  c.halves = out[0], c.frustum_culled = out[1], c.cut_culled = out[2];
  c.lod_dropped = out[3], c.occlusion_culled = out[4], c.drawn = out[5];
  c.grouping_reused = out[6];
  stats->bonds = c;
}

CompositeSummary summarize_composite(MPI_Comm comm, const CompositeStats &local,
                                     const CompositeCostModel *model) {
  const CompositeTraffic &t = local.traffic;
  const std::vector<RankSpread> s = reduce_rank_spreads(
      comm, 0,
      {double(t.bytes_sent), double(t.bytes_received), double(t.messages_sent),
       double(t.messages_received), double(local.active_pixels), t.work_cpu_ms});
  CompositeSummary c;
  c.schedule = local.schedule;
  c.model_ms = local.model_ms;
  if (model && !local.schedule.empty()) c.model = *model;
  c.bytes_sent = s[0], c.bytes_received = s[1], c.messages_sent = s[2];
  c.messages_received = s[3], c.active_pixels = s[4], c.work_cpu_ms = s[5];
  return c;
}

nlohmann::json CompositeSummary::to_json() const {
  nlohmann::json j = {{"schedule", schedule},
                      {"model_ms", model_ms},
                      {"bytes_sent", bytes_sent.to_json()},
                      {"bytes_received", bytes_received.to_json()},
                      {"messages_sent", messages_sent.to_json()},
                      {"messages_received", messages_received.to_json()},
                      {"active_pixels", active_pixels.to_json()},
                      {"work_cpu_ms", work_cpu_ms.to_json()}};
  if (model)
    j["cost_model"] = {{"latency_us", model->latency_s * 1e6},
                       {"gb_per_s", model->bytes_per_s * 1e-9},
                       {"measured", model->measured},
                       {"scan_ns", model->scan_s * 1e9},
                       {"encode_ns", model->encode_s * 1e9},
                       {"merge_ns", model->merge_s * 1e9},
                       {"dense_merge_ns", model->dense_merge_s * 1e9}};
  return j;
}

std::string SceneStats::per_rank_line() const {
  if (!per_rank) return "";
  return "scene '" + name + "' per rank: " + spread_text("drawn", per_rank->drawn, "%.0f") + ", " +
         spread_text("culled", per_rank->culled, "%.0f") + ", " +
         spread_text("ms", per_rank->ms, "%.1f") + ", " +
         spread_text("particles", per_rank->particles, "%.0f");
}

nlohmann::json SceneStats::to_json() const {
  nlohmann::json j = counts_json();
  if (per_rank) j["per_rank"] = per_rank->to_json();
  if (bonds)
    j["bonds"] = {{"halves", bonds->halves},
                  {"drawn", bonds->drawn},
                  {"frustum_culled", bonds->frustum_culled},
                  {"cut_culled", bonds->cut_culled},
                  {"lod_dropped", bonds->lod_dropped},
                  {"occlusion_culled", bonds->occlusion_culled},
                  {"grouping_reused", bonds->grouping_reused}};
  if (composite) j["composite"] = composite->to_json();
  if (color_range) j["color_range"] = {(*color_range)[0], (*color_range)[1]};
  if (budget) j["budget"] = budget->to_json();
  if (movie) {
    const MovieProgress &p = movie->progress;
    j["movie"] = {{"file", p.file},         {"encoder", p.encoder},     {"frames", p.written},
                  {"queued", p.queued},     {"dropped", p.dropped},     {"behind", movie->behind},
                  {"ms", movie->submit_ms}, {"waited_ms", p.waited_ms}, {"encode_ms", p.encode_ms}};
    if (!p.error.empty()) j["movie"]["error"] = p.error;
  }
  if (probabilistic) {
    const ProbabilisticStats &p = *probabilistic;
    j["probabilistic"] = {{"iterations", p.iterations},
                          {"samples", p.samples},
                          {"meshlets",
                           {{"potentially_visible", p.meshlets[0]},
                            {"low", p.meshlets[1]},
                            {"medium", p.meshlets[2]},
                            {"occluded", p.meshlets[3]}}},
                          {"particles_culled", p.particles_culled}};
  }
  return j;
}

nlohmann::json SceneStats::counts_json() const {
  nlohmann::json j = {{"scene", name},
                      {"file", file},
                      {"ms",
                       {{"camera", camera_ms},
                        {"cull", cull_ms},
                        {"bricks", bricks_ms},
                        {"instances", instances_ms},
                        {"draw", draw_ms},
                        {"readback", readback_ms},
                        {"composite", composite_ms},
                        {"downsample", downsample_ms},
                        {"write", write_ms},
                        {"cues", cues_ms},
                        {"total", total_ms}}},
                      {"particles",
                       {{"drawn", drawn},
                        {"splatted", splatted},
                        {"culled", culled},
                        {"frustum_culled", frustum_culled},
                        {"cut_culled", cut_culled},
                        {"lod_dropped", lod_dropped},
                        {"occlusion_culled", occlusion_culled}}},
                      {"composite_method", composite_method},
                      {"occlusion", occlusion},
                      {"renderer", renderer},
                      {"samples", samples},
                      {"sample_frame", {sample_width, sample_height}},
                      {"bricks", bricks}};
  if (overlays_ms) j["ms"]["overlays"] = *overlays_ms;
  if (!ao_deposit.empty()) {
    j["ao_deposit"] = ao_deposit;
    j["ao_nodes"] = ao_nodes;
    j["ao_spacing"] = ao_spacing;
  }
  return j;
}

}  // namespace lantern
