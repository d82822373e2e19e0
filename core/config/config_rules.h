// The configuration's cross-key rules: checks that look at more than one key, and the keys whose
// allowed range depends on an earlier key. The key tables (config_loader.cpp) name them at the
// place they run: a rule after the keys it reads (rule(f)), a key reader as the key's entry.
//
// Internal to core/config: failures throw ConfigError (yaml_reader.h). Pure functions.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <string>

#include "core/config/config.h"
#include "core/config/yaml_reader.h"

namespace lantern {

// Output patterns are paths, shown whole in messages up to this many bytes (other values are cut
// after kQuotedTextLimit).
inline constexpr size_t kPathShown = 256;

// Rules: (reader, the section's mapping, its path, the section's struct so far).

// output: a given format must agree with the pattern's extension; without one, the extension
// decides (and must be an image extension).
void format_agrees_with_pattern(const YamlReader &r, const YAML::Node &output,
                                const std::string &path, OutputConfig &o);
// output: a movie without a pattern replaces the images (OutputConfig::images); with one, both
// are written.
void movie_replaces_images(const YamlReader &r, const YAML::Node &output, const std::string &path,
                           OutputConfig &o);
// output.movie: `file` is required.
void movie_has_file(const YamlReader &r, const YAML::Node &movie, const std::string &path,
                    MovieConfig &m);
// output.movie: `quality` has no meaning with `lossless: true`.
void lossless_has_no_quality(const YamlReader &r, const YAML::Node &movie, const std::string &path,
                             MovieConfig &m);
// camera: an explicit camera must not sit on its look_at point (the default [0, 0, 0] too).
void camera_looks_away(const YamlReader &r, const YAML::Node &camera, const std::string &path,
                       CameraConfig &c);
// camera.path[i]: `step` is required.
void keyframe_has_step(const YamlReader &r, const YAML::Node &keyframe, const std::string &path,
                       CameraKeyframe &k);
// camera.orbit: `degrees_per_step` is required.
void orbit_has_rate(const YamlReader &r, const YAML::Node &orbit, const std::string &path,
                    CameraOrbit &o);
// camera: a path lists at least one keyframe, steps strictly increasing, each azimuth less than a
// full turn from the previous; it and orbit move the automatic camera only (no position), and
// not both at once. Fills in the keys each keyframe leaves out (CameraKeyframe).
void camera_path_is_ordered(const YamlReader &r, const YAML::Node &camera, const std::string &path,
                            CameraConfig &c);
// density: transfer: log with a fixed range needs lo > 0.
void log_range_is_positive(const YamlReader &r, const YAML::Node &density, const std::string &path,
                           DensityConfig &d);
// scenes[i]: a super-sampled frame within kMaxSampleFramePixels.
void sample_frame_fits(const YamlReader &r, const YAML::Node &scene, const std::string &path,
                       SceneConfig &s);
// scenes[i]: occlusion: probabilistic runs in the CPU raster's pass only.
void renderer_serves_occlusion(const YamlReader &r, const YAML::Node &scene,
                               const std::string &path, SceneConfig &s);
// scenes[i]: style: density has no surface: samples 1, no depth cues and no bonds.
void density_scene_has_no_depth(const YamlReader &r, const YAML::Node &scene,
                                const std::string &path, SceneConfig &s);
// scenes[i]: background: transparent needs output that stores alpha: not JPEG, not a movie.
void transparent_output_keeps_alpha(const YamlReader &r, const YAML::Node &scene,
                                    const std::string &path, SceneConfig &s);
// labels[i]: `text` is required.
void label_has_text(const YamlReader &r, const YAML::Node &label, const std::string &path,
                    LabelConfig &l);
// scenes[i]: a legend explains color.by scalar (a bar) or type (a key, which needs type_names).
void legend_has_colors(const YamlReader &r, const YAML::Node &scene, const std::string &path,
                       SceneConfig &s);
// top level: scene names are unique, and scenes do not write the same files (images or movies).
void scenes_are_distinct(const YamlReader &r, const YAML::Node &top, const std::string &path,
                         Config &config);
// top level: at least one scene, or a dump.
void config_has_work(const YamlReader &r, const YAML::Node &top, const std::string &path,
                     Config &config);

// Key readers: (reader, the key's value, its path, the section's struct so far).

// camera.look_at: needs camera.position (read before it), and must differ from it.
void read_look_at(const YamlReader &r, const YAML::Node &value, const std::string &path,
                  CameraConfig &c);
// camera.far: beyond camera.near.
void read_far(const YamlReader &r, const YAML::Node &value, const std::string &path,
              CameraConfig &c);
// depth_cue.end: 'auto', or beyond depth_cue.start.
void read_cue_end(const YamlReader &r, const YAML::Node &value, const std::string &path,
                  DepthCueConfig &d);

}  // namespace lantern
