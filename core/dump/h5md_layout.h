// Where Lantern's H5MD files keep things: the names shared by the writer and the reader.
//
// File layout (H5MD 1.1; N particles per frame, F frames, <real> float32 or float64):
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
// Every element is an H5MD time-dependent group; its value's first axis is the frame.
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

}  // namespace lantern::h5md
