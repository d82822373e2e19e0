// Live configuration: lantern_reconfigure() and `watch: true` (the Runtime members that replace
// the configuration of a running context; runtime.h).
//
// What carries over a change: the bricks (they depend on the particles only), the GL session and
// renderer, the dump file, and each scene's buffers, asynchronous writer and per-brick cut counts,
// matched by scene name - so a scene whose cutting planes changed reclassifies only the bricks
// those planes touch (core/culling/brick_cut_counts.h). What a change invalidates is rebuilt
// lazily by the next pass (a frame of a new size, the counts of a new scene). What may not change
// is in core/config/live_change.h.
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/common/collective_status.h"
#include "core/common/content_hash.h"
#include "core/config/config_loader.h"
#include "core/config/environment.h"
#include "core/config/file_pattern.h"
#include "core/config/live_change.h"
#include "core/pipeline/memory_budget.h"
#include "core/pipeline/runtime.h"
#include "core/pipeline/scene_movie.h"
#include "core/pipeline/scene_overlays.h"

namespace lantern {
namespace {

// Collective: OK when every rank's text has rank 0's hash; else kInvalidArgument naming the
// lowest rank whose text differs and the API function given it.
Status agree_on_text(MPI_Comm comm, uint64_t hash, const char *function) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  uint64_t root = hash;
  MPI_Bcast(&root, 1, MPI_UINT64_T, 0, comm);
  const int mine = root == hash ? size : rank;
  int first = size;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == size) return {};
  return {StatusCode::kInvalidArgument,
          std::string("config: the ranks passed different configurations to ") + function +
              " (rank " + std::to_string(first) +
              "'s text differs from rank 0's; it is collective: give every rank the same "
              "document or file)"};
}

// watch: true needs a file to watch.
Status check_watch_source(const Config &config, const std::string &path) {
  if (config.watch && path.empty())
    return {StatusCode::kConfig,
            "watch: true needs the configuration to come from a file (pass its path, not an "
            "inline document)"};
  return {};
}

// True when `output` names the file at `source` (the same file through any path or link).
bool same_file(const std::string &output, const std::string &source) {
  std::error_code ec;
  if (std::filesystem::equivalent(output, source, ec)) return true;
  const auto normal = [](const std::string &p) {
    std::error_code ignored;
    return std::filesystem::weakly_canonical(p, ignored).lexically_normal();
  };
  return normal(output) == normal(source);
}

// The stats file or the dump pointing at the configuration's own file would append JSON lines to
// the configuration (or replace it by HDF5), which a watch then reads back as a broken edit.
Status check_outputs_spare_the_source(const Config &config, const std::string &path) {
  if (path.empty()) return {};
  if (!config.stats_file.empty() && same_file(config.stats_file, path))
    return {StatusCode::kConfig, "stats: '" + config.stats_file +
                                     "' is the configuration file itself; Lantern would append "
                                     "its stats lines to the configuration (give another path)"};
  if (config.dump.enabled && same_file(config.dump.file, path))
    return {StatusCode::kConfig, "dump.file: '" + config.dump.file +
                                     "' is the configuration file itself (give another path)"};
  return {};
}

// The stats lines, the dump and each scene's movie in files of their own: JSON lines appended to
// the dump (or a movie) would break its HDF5 (or MP4) structure, and the dump or a movie would
// replace the stats written so far. (Scenes' movies among themselves: config_rules.cpp.)
Status check_outputs_are_distinct(const Config &config) {
  std::vector<std::pair<std::string, std::string>> files;  // (key, file)
  if (!config.stats_file.empty()) files.emplace_back("stats", config.stats_file);
  if (config.dump.enabled) files.emplace_back("dump.file", config.dump.file);
  for (const SceneConfig &s : config.scenes)
    if (s.output.movie.enabled)
      files.emplace_back("scene '" + s.name + "': output.movie.file",
                         expand_pattern(s.output.movie.file, 0, s.name));
  for (size_t a = 0; a < files.size(); ++a)
    for (size_t b = a + 1; b < files.size(); ++b)
      if (files[a].first.rfind("scene ", 0) != 0 || files[b].first.rfind("scene ", 0) != 0)
        if (same_file(files[a].second, files[b].second))
          return {StatusCode::kConfig, files[b].first + ": '" + files[b].second + "' is also " +
                                           files[a].first +
                                           "; each output needs a file of its own"};
  return {};
}

const char *source_name(const std::string &path) {
  return path.empty() ? "inline config" : path.c_str();
}

}  // namespace

Status Runtime::load_first_config(const std::string &path_or_document) {
  std::string text;
  if (Status s = read_config_text(path_or_document, &text, &config_path_); !s.ok()) return s;
  if (Status s = load_config_text(text, source_name(config_path_), &config_); !s.ok()) return s;
  if (Status s = apply_environment(&config_); !s.ok()) return s;
  if (Status s = check_watch_source(config_, config_path_); !s.ok()) return s;
  if (Status s = check_outputs_spare_the_source(config_, config_path_); !s.ok()) return s;
  if (Status s = check_outputs_are_distinct(config_); !s.ok()) return s;
  config_hash_ = content_hash(text);
  if (config_.watch) watch_.start(config_path_, config_hash_);
  return {};
}

Status Runtime::agree_on_first_config() {
  return agree_on_text(comm_, config_hash_, "lantern_open");
}

Status Runtime::reconfigure(const std::optional<std::string> &config) {
  if (Status s = mpi_usable("lantern_reconfigure"); !s.ok()) return s;
  std::string text, path;
  const Status read =
      config ? read_config_text(*config, &text, &path)
             : Status(StatusCode::kNullArgument, "config: NULL (give a YAML path or document)");
  if (Status s = agree_on_status(comm_, read); !s.ok()) return s;
  const uint64_t hash = content_hash(text);
  if (Status s = agree_on_text(comm_, hash, "lantern_reconfigure"); !s.ok())
    return Status(s.code, s.message + "; the running configuration is kept");
  return switch_config(text, path, hash);
}

Status Runtime::switch_config(const std::string &text, const std::string &path, uint64_t hash) {
  // The same text from the same place: nothing to parse, nothing to rebuild. Agreed, because the
  // place may differ between ranks with the same text (a path on rank 0, the document inline on
  // the others): a rank that returned here would leave the others waiting in the collectives
  // below.
  int unchanged = hash == config_hash_ && path == config_path_;
  MPI_Allreduce(MPI_IN_PLACE, &unchanged, 1, MPI_INT, MPI_LAND, comm_);
  if (unchanged) return {};
  Config next;
  Status local = load_config_text(text, source_name(path), &next);
  if (local.ok()) local = apply_environment(&next);
  if (local.ok()) local = check_watch_source(next, path);
  if (local.ok()) local = check_outputs_spare_the_source(next, path);
  if (local.ok()) local = check_outputs_are_distinct(next);
  if (local.ok()) local = check_live_change(config_, next);
  const MemoryShare share = node_memory_share(comm_);  // collective: on every rank
  if (local.ok()) local = check_scene_memory(estimate_scene_memory(next), share);
  if (local.ok()) local = check_scene_movies(next.scenes);
  if (local.ok()) local = check_scene_overlays(next.scenes);
  // Without OpenGL (tried, and absent on every rank alike) a scene may not insist on it.
  for (const SceneConfig &scene : next.scenes)
    if (local.ok() && gl_tried_ && !gl_ && scene.renderer == RendererChoice::kOpenGl)
      local = {StatusCode::kConfig, "scenes '" + scene.name +
                                        "': renderer: opengl, but this context runs without "
                                        "OpenGL (use renderer: cpu or auto)"};
  if (Status s = agree_on_status(comm_, local); !s.ok()) return s;

  Config previous = std::move(config_);
  config_ = std::move(next);
  // The first scenes of a context opened for dumps only: OpenGL is chosen now (collective).
  if (!gl_tried_ && !config_.scenes.empty())
    if (Status s = open_gl(); !s.ok()) {
      config_ = std::move(previous);
      return s;
    }

  // Each scene keeps its buffers (frame, writer, cut counts) under its name; new scenes start
  // empty; removed scenes' images still in flight are finished here.
  std::vector<SceneBuffers> kept;
  kept.reserve(config_.scenes.size());
  std::vector<bool> taken(buffers_.size(), false);
  for (const SceneConfig &scene : config_.scenes) {
    size_t j = 0;
    while (j < previous.scenes.size() && (taken[j] || previous.scenes[j].name != scene.name)) ++j;
    if (j < previous.scenes.size()) {
      taken[j] = true;
      kept.emplace_back(std::move(buffers_[j]));
    } else {
      kept.emplace_back();
    }
  }
  for (size_t j = 0; j < buffers_.size(); ++j) {
    if (taken[j]) continue;
    if (Status s = buffers_[j].writer.wait(); !s.ok() && rank_ == 0)
      std::fprintf(stderr, "lantern: warning: scenes '%s' (removed by a reconfiguration): %s\n",
                   previous.scenes[j].name.c_str(), s.message.c_str());
    if (buffers_[j].movie)
      if (Status s = buffers_[j].movie->finish(); !s.ok())
        std::fprintf(stderr, "lantern: warning: scenes '%s' (removed by a reconfiguration): %s\n",
                     previous.scenes[j].name.c_str(), s.message.c_str());
  }
  buffers_.swap(kept);
  // Movies follow their scenes: new ones open, changed or dropped ones are finished. The new
  // configuration stands even if a movie cannot be opened (its scene renders without it).
  const Status movies = open_scene_movies(comm_, config_.scenes, &buffers_);

  warn_about_scenes();
  if (dump_) dump_->set_schedule(config_.dump.schedule);
  if (config_.watch)
    watch_.start(path, hash);
  else
    watch_.stop();
  config_path_ = path;
  config_hash_ = hash;
  ++config_changes_;
  return movies.ok() ? Status()
                     : Status(movies.code,
                              movies.message + " (the new configuration took effect without it)");
}

bool Runtime::follow_config_file(int64_t step) {
  std::string text, problem;
  const std::string path = watch_.path();
  const bool changed = watch_.poll(comm_, &text, &problem);
  const auto report = [&](const std::string &what) {  // once per problem: stderr and stats line
    if (rank_ != 0) return;
    std::fprintf(stderr, "lantern: warning: step %lld: %s\n", static_cast<long long>(step),
                 what.c_str());
    config_event_ = what;
  };
  if (!problem.empty()) report(problem);
  if (!changed) return false;
  // switch_config is collective and every rank has the same text: no agreement on it needed.
  const Status s = switch_config(text, path, content_hash(text));
  if (!s.ok()) {
    report("config file '" + path +
           "' not applied, keeping the last good configuration: " + s.message);
    return false;
  }
  if (rank_ == 0) config_event_ = "reloaded '" + path + "'";
  return true;
}

}  // namespace lantern
