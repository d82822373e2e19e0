// One name <-> value table per configuration enum: the configuration loader parses the YAML
// words with them, and the stats lines and messages print the same words, so a value is spelled
// in exactly one place.
//
// Each table lists the canonical name first for every value; aliases accepted when reading
// (e.g. "jpg" for jpeg) follow with the same value. Thread-safety: constant data.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/config/config.h"

namespace lantern {

template <typename E>
struct EnumName {
  E value;
  const char *name;
};

inline constexpr EnumName<OcclusionMode> kOcclusionModeNames[] = {
    {OcclusionMode::kAuto, "auto"},
    {OcclusionMode::kNone, "none"},
    {OcclusionMode::kNineSpheres, "nine_spheres"},
    {OcclusionMode::kNineSpheresSorted, "nine_spheres_sorted"},
    {OcclusionMode::kHzb, "hzb"},
    {OcclusionMode::kProbabilistic, "probabilistic"}};

inline constexpr EnumName<NineSpheresRadius> kNineSpheresRadiusNames[] = {
    {NineSpheresRadius::kWorld, "world"}, {NineSpheresRadius::kEquivalent, "equivalent"}};

inline constexpr EnumName<RendererChoice> kRendererChoiceNames[] = {
    {RendererChoice::kAuto, "auto"},
    {RendererChoice::kOpenGl, "opengl"},
    {RendererChoice::kCpu, "cpu"}};

inline constexpr EnumName<Projection> kProjectionNames[] = {
    {Projection::kPerspective, "perspective"}, {Projection::kOrthographic, "orthographic"}};

inline constexpr EnumName<ColorBy> kColorByNames[] = {
    {ColorBy::kSolid, "solid"}, {ColorBy::kType, "type"}, {ColorBy::kScalar, "scalar"}};

inline constexpr EnumName<ImageFormat> kImageFormatNames[] = {
    {ImageFormat::kPng, "png"},   {ImageFormat::kJpeg, "jpeg"}, {ImageFormat::kJpeg, "jpg"},
    {ImageFormat::kTiff, "tiff"}, {ImageFormat::kTiff, "tif"},  {ImageFormat::kExr, "exr"}};

inline constexpr EnumName<GlBackend> kGlBackendNames[] = {{GlBackend::kAuto, "auto"},
                                                          {GlBackend::kEgl, "egl"},
                                                          {GlBackend::kOsmesa, "osmesa"},
                                                          {GlBackend::kNone, "none"}};

inline constexpr EnumName<SceneStyle> kSceneStyleNames[] = {{SceneStyle::kSpheres, "spheres"},
                                                            {SceneStyle::kDensity, "density"}};

inline constexpr EnumName<DensityTransfer> kDensityTransferNames[] = {
    {DensityTransfer::kLinear, "linear"},
    {DensityTransfer::kLog, "log"},
    {DensityTransfer::kAsinh, "asinh"}};

inline constexpr EnumName<LodSelect> kLodSelectNames[] = {{LodSelect::kUniform, "uniform"},
                                                          {LodSelect::kNearest, "nearest"}};
inline constexpr EnumName<AutoRange> kAutoRangeNames[] = {
    {AutoRange::kFrame, "frame"}, {AutoRange::kFirst, "first"}, {AutoRange::kRunning, "running"}};
inline constexpr EnumName<MovieWhenBehind> kMovieWhenBehindNames[] = {
    {MovieWhenBehind::kDrop, "drop"}, {MovieWhenBehind::kWait, "wait"}};
inline constexpr EnumName<DumpMode> kDumpModeNames[] = {{DumpMode::kCreate, "create"},
                                                        {DumpMode::kAppend, "append"},
                                                        {DumpMode::kOverwrite, "overwrite"}};

inline constexpr EnumName<OverlayCorner> kOverlayCornerNames[] = {
    {OverlayCorner::kTopLeft, "top_left"},
    {OverlayCorner::kTopRight, "top_right"},
    {OverlayCorner::kBottomLeft, "bottom_left"},
    {OverlayCorner::kBottomRight, "bottom_right"}};

inline constexpr EnumName<BondColorBy> kBondColorByNames[] = {{BondColorBy::kAtom, "by_atom"},
                                                              {BondColorBy::kType, "by_type"},
                                                              {BondColorBy::kSolid, "solid"}};

// The table of each enum, so that name_of / value_of / names_of need only the enum type.
inline constexpr const auto &names_table(OcclusionMode) {
  return kOcclusionModeNames;
}
inline constexpr const auto &names_table(NineSpheresRadius) {
  return kNineSpheresRadiusNames;
}
inline constexpr const auto &names_table(RendererChoice) {
  return kRendererChoiceNames;
}
inline constexpr const auto &names_table(Projection) {
  return kProjectionNames;
}
inline constexpr const auto &names_table(ColorBy) {
  return kColorByNames;
}
inline constexpr const auto &names_table(ImageFormat) {
  return kImageFormatNames;
}
inline constexpr const auto &names_table(GlBackend) {
  return kGlBackendNames;
}
inline constexpr const auto &names_table(SceneStyle) {
  return kSceneStyleNames;
}
inline constexpr const auto &names_table(DensityTransfer) {
  return kDensityTransferNames;
}
inline constexpr const auto &names_table(LodSelect) {
  return kLodSelectNames;
}
inline constexpr const auto &names_table(BondColorBy) {
  return kBondColorByNames;
}
inline constexpr const auto &names_table(AutoRange) {
  return kAutoRangeNames;
}
inline constexpr const auto &names_table(MovieWhenBehind) {
  return kMovieWhenBehindNames;
}
inline constexpr const auto &names_table(DumpMode) {
  return kDumpModeNames;
}

inline constexpr const auto &names_table(OverlayCorner) {
  return kOverlayCornerNames;
}

// The canonical name of `value` ("?" for a value missing from its table: a bug).
template <typename E>
const char *name_of(E value) {
  for (const EnumName<E> &entry : names_table(E{}))
    if (entry.value == value) return entry.name;
  return "?";
}

// The value named `name` (canonical or alias), if any.
template <typename E>
std::optional<E> value_of(std::string_view name) {
  for (const EnumName<E> &entry : names_table(E{}))
    if (name == entry.name) return entry.value;
  return std::nullopt;
}

// Every accepted name, canonical and aliases, in table order (for "must be one of ..." errors).
template <typename E>
std::vector<std::string> names_of() {
  std::vector<std::string> names;
  for (const EnumName<E> &entry : names_table(E{})) names.emplace_back(entry.name);
  return names;
}

}  // namespace lantern
