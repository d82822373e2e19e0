// The movie side of a scene's output (output.movie): which scenes have a movie open on rank 0,
// handing each composited frame to it, and finishing the files. The encoding itself runs on the
// movie's own thread (core/output/movie/movie_writer.h), so a step pays only for a frame copy.
// The frames are the composited image, so a movie is rank-invariant exactly as the images are.
#pragma once

#include <mpi.h>

#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/config/config.h"
#include "core/pipeline/scene_pass_inputs.h"
#include "core/pipeline/scene_stats.h"

namespace lantern {

// The file of a scene's movie ({scene} expanded).
std::string movie_path(const SceneConfig &scene);

// Local, the same on every rank: every movie's settings are ones this build can encode (kConfig
// naming the scene and key, listing the build's codecs; or saying the build has no movies).
Status check_scene_movies(const std::vector<SceneConfig> &scenes);

// Collective: makes rank 0's open movies match `scenes` (buffers[i] belongs to scenes[i]): opens
// the movies not open yet, finishes those whose scene dropped or changed its movie. kIo naming
// the file when one cannot be written (at lantern_open: before any step runs). Same status on
// every rank.
Status open_scene_movies(MPI_Comm comm, const std::vector<SceneConfig> &scenes,
                         std::vector<SceneBuffers> *buffers);

// Rank 0, after compositing: queues `frame` for the scene's movie (if it has one) and fills
// stats->movie. OK, or once the error that stopped the movie (the images go on).
Status send_frame_to_movie(const SceneConfig &scene, const Frame &frame, SceneBuffers *buffers,
                           SceneStats *stats);

// Local: encodes what is queued and completes every movie file this rank holds (rank 0's; none
// elsewhere). OK, or the first movie's error, naming its scene. No MPI call: lantern_close after
// the host's MPI_Finalize still completes the files.
Status finish_movies_on_this_rank(const std::vector<SceneConfig> &scenes,
                                  std::vector<SceneBuffers> *buffers);

// Collective: finish_movies_on_this_rank, then its status shared (lantern_close). Same status
// on every rank: the first movie's error, naming its scene.
Status finish_scene_movies(MPI_Comm comm, const std::vector<SceneConfig> &scenes,
                           std::vector<SceneBuffers> *buffers);

}  // namespace lantern
