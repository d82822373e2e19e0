#include "core/config/config_rules.h"

#include <cctype>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>

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
