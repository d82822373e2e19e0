// Where Lantern's H5MD files keep things: the names shared by the writer and the reader.
//
// File layout (H5MD 1.1; F frames, N = the largest particle count of any frame so far, <real>
// float32 or float64):
//   /h5md                      +-- version int32[2] = {1, 1}
//        /author               +-- name
//        /creator              +-- name = "Lantern", version
//   /particles/all/box         +-- dimension = 3, boundary = string[3] ("periodic" | "none")
//                 /edges       {value float64[F][3], step int64[F], time float64[F]}
//                 /offset      {value ...[F][3], ...}  lower corner (Lantern's addition: H5MD
//                                                      boxes have no origin; tools ignore it)
//   /particles/all/position    {value <real>[F][N][3], step, time}
//   /particles/all/species     {value int32[F][N], ...}   (optional: the published type)
//   /particles/all/id          {value int64[F][N], ...}   (optional)
//   /particles/all/scalar      {value <real>[F][N], ...}  (optional)
//   /particles/all/radius      {value <real>[F][N], ...}  (optional)
//   /connectivity/all_bonds    {value int64[F][B][2], step, time}  (only when bonds are published)
//                              +-- particles_group: object reference to /particles/all
//   /observables/particle_count {value int64[F], step, time}  particles in each frame
// Every element is an H5MD time-dependent group; its value's first axis is the frame. The N
// axis is extensible: a frame of n < N particles holds them in rows [0, n) and the dataset's
// fill value after them (NaN in real fields, -1 in species and id; an id equal to the fill
// value is H5MD's "no particle", which lets a particle number vary in time).
// The bonds (H5MD 1.1 connectivity, a time-dependent list of pairs) hold particle ids (the `id`
// element, which a file with bonds always has): each bond once, in no particular order; B is the
// largest bond count so far and a frame's unused pairs hold the fill value -1 (H5MD: a pair of
// fill values is no bond). Time-dependent because a run's bonds may change (bonds formed or
// broken, a group whose members change); a run whose bonds never change writes the same list
// each frame, which costs 16 bytes per bond per frame beside 24 per particle for positions.
// A frame's datasets are extended in the order above, particle_count last. A frame that fails
// part-way is cut back from every dataset once the file is closed (frame_cut_back.h), so every
// element then has as many frames as particle_count/time: the complete ones. Only if cutting
// back failed too (the dump's error says so) may other datasets stay one frame longer.
#pragma once

namespace lantern::h5md {

inline constexpr const char *kParticles = "/particles";
inline constexpr const char *kGroupName = "all";
inline constexpr const char *kPosition = "position";
inline constexpr const char *kSpecies = "species";
inline constexpr const char *kId = "id";
inline constexpr const char *kScalar = "scalar";
inline constexpr const char *kRadius = "radius";
inline constexpr const char *kBox = "box";
inline constexpr const char *kConnectivity = "/connectivity";
inline constexpr const char *kBondsName = "all_bonds";
inline constexpr const char *kBonds = "/connectivity/all_bonds";
inline constexpr const char *kParticlesGroupAttribute = "particles_group";
inline constexpr const char *kObservables = "/observables";
inline constexpr const char *kParticleCountName = "particle_count";
inline constexpr const char *kParticleCount = "/observables/particle_count";

}  // namespace lantern::h5md
