#include "core/pipeline/scene_movie.h"

#include <chrono>
#include <cstdio>

#include "core/common/collective_status.h"
#include "core/common/guarded_status.h"
#include "core/common/ms_since.h"
#include "core/config/file_pattern.h"
#include "core/output/movie/movie_encoder.h"

namespace lantern {
namespace {

std::string where(const SceneConfig &scene) {
  return "scenes '" + scene.name + "': ";
}

// True when the open movie can go on taking this scene's frames.
bool same_movie(const MovieWriter &open, const SceneConfig &scene) {
  return scene.output.movie.enabled && open.config() == scene.output.movie &&
         open.width() == scene.width && open.height() == scene.height;
}

}  // namespace

std::string movie_path(const SceneConfig &scene) {
  return expand_pattern(scene.output.movie.file, 0, scene.name);
}

Status check_scene_movies(const std::vector<SceneConfig> &scenes) {
  for (const SceneConfig &scene : scenes)
    if (scene.output.movie.enabled)
      if (Status s = check_movie_config(scene.output.movie, movie_path(scene)); !s.ok())
        return with_context(where(scene), std::move(s));
  return {};
}

Status open_scene_movies(MPI_Comm comm, const std::vector<SceneConfig> &scenes,
                         std::vector<SceneBuffers> *buffers) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  Status first;
  if (rank == 0)
    first = guarded_status("movie", [&]() -> Status {
      Status first_failure;
      for (size_t i = 0; i < scenes.size() && i < buffers->size(); ++i) {
        const SceneConfig &scene = scenes[i];
        std::unique_ptr<MovieWriter> &movie = (*buffers)[i].movie;
        if (movie && !same_movie(*movie, scene)) {
          if (Status s = movie->finish(); !s.ok())
            std::fprintf(stderr, "lantern: warning: %s%s\n", where(scene).c_str(),
                         s.message.c_str());
          movie.reset();
        }
        if (movie || !scene.output.movie.enabled) continue;
        (*buffers)[i].movie_warned = false;
        const Status s = MovieWriter::open(scene.output.movie, movie_path(scene), scene.width,
                                           scene.height, &movie);
        if (!s.ok() && first_failure.ok()) first_failure = with_context(where(scene), s);
      }
      return first_failure;
    });
  return broadcast_status(comm, first, 0);
}

Status send_frame_to_movie(const SceneConfig &scene, const Frame &frame, SceneBuffers *buffers,
                           SceneStats *stats) {
  MovieWriter *movie = buffers->movie.get();
  if (!movie) return {};
  const auto t0 = std::chrono::steady_clock::now();
  const int64_t dropped_before = movie->progress().dropped;
  const Status sent = with_context(where(scene), movie->submit(frame));
  SceneMovieStats out;
  out.progress = movie->progress();
  out.submit_ms = ms_since(t0);
  out.behind = out.progress.dropped > dropped_before || out.progress.waited_ms > 0.0;
  if (out.progress.dropped > dropped_before && !buffers->movie_warned) {
    buffers->movie_warned = true;  // once per movie; the stats line counts every drop
    std::fprintf(stderr,
                 "lantern: warning: %sthe movie encoder is behind: frames are left out of '%s' "
                 "(counted as movie.dropped in the stats; output.movie.when_behind: wait or a "
                 "larger queue keeps every frame)\n",
                 where(scene).c_str(), out.progress.file.c_str());
  }
  stats->movie = out;
  return sent;
}

Status finish_movies_on_this_rank(const std::vector<SceneConfig> &scenes,
                                  std::vector<SceneBuffers> *buffers) {
  Status first;
  for (size_t i = 0; i < buffers->size(); ++i) {
    std::unique_ptr<MovieWriter> &movie = (*buffers)[i].movie;
    if (!movie) continue;
    const Status s = movie->finish();
    if (!s.ok() && first.ok())
      first = with_context(i < scenes.size() ? where(scenes[i]) : std::string(), s);
  }
  return first;
}

Status finish_scene_movies(MPI_Comm comm, const std::vector<SceneConfig> &scenes,
                           std::vector<SceneBuffers> *buffers) {
  return broadcast_status(comm, finish_movies_on_this_rank(scenes, buffers), 0);
}

}  // namespace lantern
