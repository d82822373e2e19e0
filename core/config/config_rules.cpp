#include "core/config/config_rules.h"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include "core/common/quoted_text.h"
#include "core/config/enum_names.h"
#include "core/config/file_pattern.h"

namespace lantern {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string lower(std::string s) {
  for (char &c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::optional<ImageFormat> format_of_extension(const std::string &pattern) {
  const std::string extension = lower(std::filesystem::path(pattern).extension().string());
  if (extension.size() < 2) return std::nullopt;
  return value_of<ImageFormat>(extension.substr(1));
}

// The value of `key` in a section's mapping; undefined (no line in messages) when absent.
YAML::Node key_node(const YAML::Node &section, const char *key) {
  return section.IsMap() ? section[key] : YAML::Node(YAML::NodeType::Undefined);
}

// Degrees as a person writes them: 400, not 400.000000.
std::string degrees_text(double degrees) {
  std::ostringstream s;
  s << degrees;
  return s.str();
}

}  // namespace

void format_agrees_with_pattern(const YamlReader &r, const YAML::Node &output,
                                const std::string &path, OutputConfig &o) {
  const std::optional<ImageFormat> from_extension = format_of_extension(o.pattern);
  const YAML::Node format = key_node(output, "format");
  if (format.IsDefined() && !format.IsNull()) {
    if (from_extension && *from_extension != o.format)
      r.fail(format, child_path(path, "format"),
             quoted_text(format.Scalar()) + " contradicts the extension of output.pattern " +
                 quoted_text(o.pattern, kPathShown));
    return;
  }
  if (!from_extension)
    r.fail(key_node(output, "pattern"), child_path(path, "pattern"),
           quoted_text(o.pattern, kPathShown) +
               " has no image extension (.png, .jpg, .jpeg, .tif, .tiff, .exr); add one or "
               "set output.format");
  o.format = *from_extension;
}

void movie_replaces_images(const YamlReader &, const YAML::Node &output, const std::string &,
                           OutputConfig &o) {
  const YAML::Node pattern = key_node(output, "pattern");
  if (o.movie.enabled && !(pattern.IsDefined() && !pattern.IsNull())) o.images = false;
}

void movie_has_file(const YamlReader &r, const YAML::Node &movie, const std::string &path,
                    MovieConfig &) {
  const YAML::Node file = key_node(movie, "file");
  if (!file.IsDefined() || file.IsNull())
    r.fail(movie, path, "needs 'file' (e.g. file: 'out/{scene}.mp4')");
}

void label_has_text(const YamlReader &r, const YAML::Node &label, const std::string &path,
                    LabelConfig &) {
  const YAML::Node text = key_node(label, "text");
  if (!text.IsDefined() || text.IsNull())
    r.fail(label, path, "needs 'text' (e.g. text: 'step {step}  t = {time:.2f}')");
}

void legend_has_colors(const YamlReader &r, const YAML::Node &scene, const std::string &path,
                       SceneConfig &s) {
  if (!s.legend.enabled) return;
  const YAML::Node legend = key_node(scene, "legend");
  const std::string at = child_path(path, "legend");
  if (s.color.by == ColorBy::kSolid)
    r.fail(legend, at,
           "explains colors by scalar (a colour bar) or by type (a key); this scene's color.by "
           "is solid");
  if (s.color.by == ColorBy::kType && s.legend.type_names.empty())
    r.fail(legend, at,
           "with color.by: type needs type_names: [name of type 0, name of type 1, ...]");
}

void lossless_has_no_quality(const YamlReader &r, const YAML::Node &movie, const std::string &path,
                             MovieConfig &m) {
  if (m.lossless && m.quality)
    r.fail(key_node(movie, "quality"), child_path(path, "quality"),
           "does not apply with lossless: true (remove one of the two)");
}

void camera_looks_away(const YamlReader &r, const YAML::Node &camera, const std::string &path,
                       CameraConfig &c) {
  if (c.position && c.look_at == *c.position)  // look_at defaulted to the origin
    r.fail(key_node(camera, "position"), child_path(path, "position"),
           "the explicit camera looks at look_at (default [0, 0, 0]); position must differ");
}

void keyframe_has_step(const YamlReader &r, const YAML::Node &keyframe, const std::string &path,
                       CameraKeyframe &) {
  const YAML::Node step = key_node(keyframe, "step");
  if (!step.IsDefined() || step.IsNull())
    r.fail(keyframe, path, "needs 'step' (the simulation step this view belongs to)");
}

void orbit_has_rate(const YamlReader &r, const YAML::Node &orbit, const std::string &path,
                    CameraOrbit &) {
  const YAML::Node rate = key_node(orbit, "degrees_per_step");
  if (!rate.IsDefined() || rate.IsNull())
    r.fail(orbit, path, "needs 'degrees_per_step' (e.g. orbit: {degrees_per_step: 0.5})");
}

// Keyframes are checked in the order written: the first one out of order is named. An azimuth
// difference of a full turn or more has no single rotation on the sphere (0 and 360 are the
// same view), so such a turn needs a keyframe in between.
void camera_path_is_ordered(const YamlReader &r, const YAML::Node &camera, const std::string &path,
                            CameraConfig &c) {
  const YAML::Node path_node = key_node(camera, "path");
  const std::string path_path = child_path(path, "path");
  if (path_node.IsDefined() && !path_node.IsNull() && c.path.empty())
    r.fail(path_node, path_path, "must list at least one keyframe {step, azimuth, ...}");
  if (c.path.empty() && !c.orbit.enabled) return;
  const YAML::Node moving = c.path.empty() ? key_node(camera, "orbit") : path_node;
  const std::string moving_path = c.path.empty() ? child_path(path, "orbit") : path_path;
  if (c.position)
    r.fail(moving, moving_path,
           "moves the automatic camera (azimuth, elevation, zoom); it cannot move an explicit "
           "camera (camera.position): remove one of the two");
  if (!c.path.empty() && c.orbit.enabled)
    r.fail(key_node(camera, "orbit"), child_path(path, "orbit"),
           "is the short form of a path: give camera.path or camera.orbit, not both");
  double azimuth = c.azimuth, elevation = c.elevation, zoom = c.zoom;
  for (size_t i = 0; i < c.path.size(); ++i) {
    CameraKeyframe &k = c.path[i];
    const std::string at = index_path(path_path, i);
    if (i > 0 && k.step <= c.path[i - 1].step)
      r.fail(path_node[i], at,
             "step " + std::to_string(k.step) + " is not after the previous keyframe's step " +
                 std::to_string(c.path[i - 1].step) +
                 " (keyframes are listed in increasing step order)");
    if (k.azimuth && i > 0 && !(std::abs(*k.azimuth - azimuth) < 360.0))
      r.fail(key_node(path_node[i], "azimuth"), child_path(at, "azimuth"),
             "turns " + degrees_text(*k.azimuth - azimuth) +
                 " degrees from the previous keyframe's azimuth; a turn of 360 degrees or more is "
                 "not one "
                 "rotation: add a keyframe in between");
    azimuth = k.azimuth.value_or(azimuth);
    elevation = k.elevation.value_or(elevation);
    zoom = k.zoom.value_or(zoom);
    k.azimuth = azimuth;
    k.elevation = elevation;
    k.zoom = zoom;
  }
}

// A fixed range under the log transfer must be positive: log(0) has no picture.
void log_range_is_positive(const YamlReader &r, const YAML::Node &density, const std::string &path,
                           DensityConfig &d) {
  if (d.transfer == DensityTransfer::kLog && d.range && (*d.range)[0] <= 0.0)
    r.fail(key_node(density, "range"), child_path(path, "range"),
           "transfer: log needs a range with lo > 0 (or 'auto'), got lo = " +
               std::to_string((*d.range)[0]));
}

// Refused here, at lantern_open, rather than failing an allocation mid-run.
void sample_frame_fits(const YamlReader &r, const YAML::Node &scene, const std::string &path,
                       SceneConfig &s) {
  const int64_t pixels = int64_t(s.width) * s.height * s.samples;
  if (s.samples == 1 || pixels <= kMaxSampleFramePixels) return;
  r.fail(key_node(scene, "samples"), child_path(path, "samples"),
         "scene " + quoted_text(s.name) + ": " + std::to_string(s.width) + " x " +
             std::to_string(s.height) + " at " + std::to_string(s.samples) +
             " samples needs a sample frame of " + std::to_string(pixels) + " pixels, " +
             std::to_string(pixels * 8) + " bytes (RGBA8 + float depth) per rank; the limit is " +
             std::to_string(kMaxSampleFramePixels) + " pixels (" +
             std::to_string(kMaxSampleFramePixels * 8) + " bytes): lower samples, width or height");
}

// Probabilistic occlusion culling with confidence maps (Ibrahim et al.) runs inside the CPU
// raster's pass only.
void renderer_serves_occlusion(const YamlReader &r, const YAML::Node &scene,
                               const std::string &path, SceneConfig &s) {
  if (s.culling.occlusion == OcclusionMode::kProbabilistic && s.renderer == RendererChoice::kOpenGl)
    r.fail(key_node(scene, "renderer"), child_path(path, "renderer"),
           "'opengl' cannot serve culling.occlusion 'probabilistic' (a renderer that cannot "
           "serve it); allowed with probabilistic: auto, cpu");
}

// A density image is a sum of smooth footprints with no surface: nothing to super-sample and no
// depth for the screen-space cues to read, so those keys are refused rather than ignored.
void density_scene_has_no_depth(const YamlReader &r, const YAML::Node &scene,
                                const std::string &path, SceneConfig &s) {
  if (s.style != SceneStyle::kDensity) return;
  if (s.samples != 1)
    r.fail(key_node(scene, "samples"), child_path(path, "samples"),
           "must be 1 with style: density (footprints are already smooth); allowed: 1");
  for (const char *cue : {"ambient_occlusion", "outline", "depth_cue"})
    if (key_node(scene, cue).IsDefined())
      r.fail(key_node(scene, cue), child_path(path, cue),
             "needs style: spheres (a density image has no depth to cue)");
  if (key_node(scene, "bonds").IsDefined())
    r.fail(key_node(scene, "bonds"), child_path(path, "bonds"),
           "needs style: spheres (bonds are drawn as cylinders among the spheres)");
}

void transparent_output_keeps_alpha(const YamlReader &r, const YAML::Node &scene,
                                    const std::string &path, SceneConfig &s) {
  if (!s.transparent_background) return;
  // Flattening onto a colour here would guess one the user never chose: say so instead.
  const YAML::Node background = key_node(scene, "background");
  const std::string where = child_path(path, "background");
  if (s.output.images && s.output.format == ImageFormat::kJpeg)
    r.fail(background, where,
           "'transparent' needs an image format with alpha, but output writes JPEG (" +
               quoted_text(s.output.pattern, kPathShown) +
               "), which has none; use .png, .tif or .exr, or give a colour [r, g, b]");
  if (s.output.movie.enabled)
    r.fail(background, where,
           "'transparent' cannot be kept by output.movie (" +
               quoted_text(s.output.movie.file, kPathShown) +
               "): movie frames are written without alpha; give a colour [r, g, b] for "
               "the movie, or write PNG, TIFF or EXR images only");
}

void scenes_are_distinct(const YamlReader &r, const YAML::Node &top, const std::string &path,
                         Config &config) {
  const YAML::Node scenes = key_node(top, "scenes");
  const std::string scenes_path = child_path(path, "scenes");
  std::map<std::string, size_t> by_name;
  std::map<std::string, size_t> by_pattern;  // patterns without {scene}
  std::map<std::string, size_t> by_movie;    // movie files, {scene} expanded
  for (size_t i = 0; i < config.scenes.size(); ++i) {
    const SceneConfig &s = config.scenes[i];
    const std::string scene_path = index_path(scenes_path, i);
    const auto [named, fresh_name] = by_name.emplace(s.name, i);
    if (!fresh_name)
      r.fail(scenes[i], child_path(scene_path, "name"),
             "scene name " + quoted_text(s.name) + " is already used by " +
                 index_path(scenes_path, named->second));
    if (s.output.movie.enabled) {
      const std::string file = expand_pattern(s.output.movie.file, 0, s.name);
      const auto [same, fresh_movie] = by_movie.emplace(file, i);
      if (!fresh_movie)
        r.fail(key_node(key_node(key_node(scenes[i], "output"), "movie"), "file"),
               child_path(scene_path, "output.movie.file"),
               quoted_text(file, kPathShown) + " is also the movie of " +
                   index_path(scenes_path, same->second) +
                   "; the scenes would write one file (add {scene})");
    }
    if (!s.output.images || pattern_uses_scene(s.output.pattern)) continue;
    const auto [same, fresh_pattern] = by_pattern.emplace(s.output.pattern, i);
    if (!fresh_pattern)
      r.fail(scenes[i], child_path(scene_path, "output.pattern"),
             quoted_text(s.output.pattern, kPathShown) + " is also the pattern of " +
                 index_path(scenes_path, same->second) +
                 "; the scenes would overwrite each other's images (add {scene})");
  }
}

void config_has_work(const YamlReader &r, const YAML::Node &top, const std::string &path,
                     Config &config) {
  if (config.scenes.empty() && !config.dump.enabled)
    r.fail(top, path, "nothing to do: add at least one entry under 'scenes:' (or a 'dump:')");
}

void read_look_at(const YamlReader &r, const YAML::Node &value, const std::string &path,
                  CameraConfig &c) {
  if (!c.position)
    r.fail(value, path, "look_at needs an explicit camera: set camera.position as well");
  c.look_at = r.read_vec3(value, path);
  if (c.look_at == *c.position) r.fail(value, path, "must differ from camera.position");
}

void read_far(const YamlReader &r, const YAML::Node &value, const std::string &path,
              CameraConfig &c) {
  c.far_plane = r.read_in_range(value, path, c.near_plane.value_or(0.0), false, kInf, false);
}

void read_cue_end(const YamlReader &r, const YAML::Node &value, const std::string &path,
                  DepthCueConfig &d) {
  if (value.IsScalar() && value.Scalar() == "auto") return;
  d.end = r.read_in_range(value, path, d.start.value_or(0.0), false, kInf, false);
}

}  // namespace lantern
