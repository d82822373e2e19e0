#include "core/config/config_loader.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "core/common/quoted_text.h"
#include "core/config/enum_names.h"
#include "core/config/file_pattern.h"
#include "core/config/yaml_reader.h"

namespace lantern {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int64_t kMaxInt = std::numeric_limits<int64_t>::max();
// Output patterns are paths, shown whole in messages up to this many bytes (other values are cut
// after kQuotedTextLimit).
constexpr size_t kPathShown = 256;

// The keys of every section: the schema. README.md (config/) documents the same keys.
const std::vector<std::string> kTopKeys = {"schedule",   "scenes", "stats", "verbose", "dump", "gl",
                                           "egl_device", "lammps", "watch", "threads"};
const std::vector<std::string> kScheduleKeys = {"every", "start", "steps"};
const std::vector<std::string> kSceneKeys = {
    "name",    "width",     "height", "background", "radius",   "camera",  "color",
    "output",  "culling",   "lod",    "cut_planes", "renderer", "samples", "ambient_occlusion",
    "outline", "depth_cue", "style",  "density",    "opacity",  "lighting"};
const std::vector<std::string> kCameraKeys = {"projection", "fov",      "azimuth", "elevation",
                                              "zoom",       "position", "look_at", "up",
                                              "near",       "far"};
const std::vector<std::string> kColorKeys = {"by", "solid", "palette", "colormap", "range"};
const std::vector<std::string> kOutputKeys = {"pattern",           "format",       "jpeg_quality",
                                              "compression_level", "asynchronous", "exr_color"};
const std::vector<std::string> kCullingKeys = {"frustum",
                                               "occlusion",
                                               "nine_spheres_radius",
                                               "confidence",
                                               "probabilistic_budget",
                                               "probabilistic_patience"};
const std::vector<std::string> kLodKeys = {"budget", "fraction", "min_pixels", "point_path",
                                           "select"};
const std::vector<std::string> kAmbientOcclusionKeys = {"method", "radius", "samples", "strength"};
const std::vector<std::string> kOutlineKeys = {"width", "color", "depth_threshold"};
const std::vector<std::string> kDepthCueKeys = {"start", "end", "color"};
const std::vector<std::string> kDensityKeys = {"transfer", "range", "colormap"};
const std::vector<std::string> kLightingKeys = {"direction", "ambient", "diffuse", "specular",
                                                "shininess"};
const std::vector<std::string> kCutPlaneKeys = {"normal", "offset", "enabled"};
const std::vector<std::string> kDumpKeys = {"enabled", "file", "schedule", "fields", "precision"};
const std::vector<std::string> kDumpFields = {"position", "type", "scalar", "radius", "id"};
const std::vector<std::string> kLammpsKeys = {"fix", "scalar"};
const std::vector<std::string> kColormaps = {"viridis", "plasma", "coolwarm", "grayscale"};

std::string lower(std::string s) {
  for (char &c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Calls `read(value_node, key_path)` if `key` is present (and not null) in `map`.
template <typename Read>
void optional_key(const YAML::Node &map, const std::string &path, const std::string &key,
                  Read read) {
  if (!map.IsMap()) return;
  const YAML::Node value = map[key];
  if (value.IsDefined() && !value.IsNull()) read(value, child_path(path, key));
}

// key -> the sections it belongs to, for "'azimuth' is a key of scenes[].camera".
std::map<std::string, std::vector<std::string>> key_homes() {
  const std::vector<std::pair<const char *, const std::vector<std::string> *>> sections = {
      {"the top level", &kTopKeys},
      {"schedule", &kScheduleKeys},
      {"scenes[]", &kSceneKeys},
      {"scenes[].camera", &kCameraKeys},
      {"scenes[].color", &kColorKeys},
      {"scenes[].output", &kOutputKeys},
      {"scenes[].culling", &kCullingKeys},
      {"scenes[].lod", &kLodKeys},
      {"scenes[].cut_planes[]", &kCutPlaneKeys},
      {"scenes[].ambient_occlusion", &kAmbientOcclusionKeys},
      {"scenes[].outline", &kOutlineKeys},
      {"scenes[].depth_cue", &kDepthCueKeys},
      {"scenes[].density", &kDensityKeys},
      {"scenes[].lighting", &kLightingKeys},
      {"dump", &kDumpKeys},
      {"lammps", &kLammpsKeys}};
  std::map<std::string, std::vector<std::string>> homes;
  for (const auto &[section, keys] : sections)
    for (const std::string &key : *keys) homes[key].push_back(section);
  return homes;
}

class Loader {
 public:
  explicit Loader(std::string source) : r_(std::move(source)) { r_.set_key_homes(key_homes()); }

  Config load(const YAML::Node &root) const {
    if (!root.IsMap() && !root.IsNull())
      r_.fail(root, "", "the configuration must be a mapping with keys (schedule, scenes, ...)");
    r_.check_map(root, "", kTopKeys);
    Config config;
    optional_key(root, "", "schedule", [&](const YAML::Node &n, const std::string &p) {
      config.schedule = schedule(n, p);
    });
    optional_key(root, "", "stats", [&](const YAML::Node &n, const std::string &p) {
      // An empty string is allowed: it is the documented way to write "no stats".
      if (n.IsScalar() && n.Scalar().empty()) return;
      config.stats_file = r_.read_string(n, p);
    });
    optional_key(root, "", "verbose", [&](const YAML::Node &n, const std::string &p) {
      config.verbose = r_.read_bool(n, p);
    });
    optional_key(root, "", "dump",
                 [&](const YAML::Node &n, const std::string &p) { config.dump = dump(n, p); });
    optional_key(root, "", "gl", [&](const YAML::Node &n, const std::string &p) {
      config.gl = read_enum<GlBackend>(n, p);
    });
    optional_key(root, "", "egl_device", [&](const YAML::Node &n, const std::string &p) {
      if (n.IsScalar() && n.Scalar() == "auto") return;
      config.egl_device = static_cast<int>(r_.read_int(n, p, 0, 1023));
    });
    optional_key(root, "", "scenes",
                 [&](const YAML::Node &n, const std::string &p) { config.scenes = scenes(n, p); });
    optional_key(root, "", "lammps",
                 [&](const YAML::Node &n, const std::string &p) { config.lammps = lammps(n, p); });
    optional_key(root, "", "watch", [&](const YAML::Node &n, const std::string &p) {
      config.watch = r_.read_bool(n, p);
    });
    optional_key(root, "", "threads", [&](const YAML::Node &n, const std::string &p) {
      if (n.IsScalar() && n.Scalar() == "auto") return;
      config.threads = static_cast<int>(r_.read_int(n, p, 1, 1024));
    });
    if (config.scenes.empty() && !config.dump.enabled)
      r_.fail(root, "", "nothing to do: add at least one entry under 'scenes:' (or a 'dump:')");
    return config;
  }

 private:
  Schedule schedule(const YAML::Node &node, const std::string &path) const {
    r_.check_map(node, path, kScheduleKeys);
    Schedule s;
    optional_key(node, path, "every", [&](const YAML::Node &n, const std::string &p) {
      s.every = r_.read_int(n, p, 0, kMaxInt);
    });
    optional_key(node, path, "start", [&](const YAML::Node &n, const std::string &p) {
      s.start = r_.read_int(n, p, 0, kMaxInt);
    });
    optional_key(node, path, "steps", [&](const YAML::Node &n, const std::string &p) {
      r_.check_sequence(n, p);
      if (n.size() == 0) r_.fail(n, p, "must list at least one step (omit it for every step)");
      for (size_t i = 0; i < n.size(); ++i)
        s.steps.push_back(r_.read_int(n[i], index_path(p, i), 0, kMaxInt));
      std::sort(s.steps.begin(), s.steps.end());
      s.steps.erase(std::unique(s.steps.begin(), s.steps.end()), s.steps.end());
    });
    return s;
  }

  std::vector<SceneConfig> scenes(const YAML::Node &node, const std::string &path) const {
    r_.check_sequence(node, path);
    std::vector<SceneConfig> out;
    std::map<std::string, size_t> by_name;
    std::map<std::string, size_t> by_pattern;  // patterns without {scene}
    for (size_t i = 0; i < node.size(); ++i) {
      const std::string scene_path = index_path(path, i);
      out.push_back(scene(node[i], scene_path, i));
      const SceneConfig &s = out.back();
      const auto [named, fresh_name] = by_name.emplace(s.name, i);
      if (!fresh_name)
        r_.fail(node[i], child_path(scene_path, "name"),
                "scene name " + quoted_text(s.name) + " is already used by " +
                    index_path(path, named->second));
      if (pattern_uses_scene(s.output.pattern)) continue;
      const auto [same, fresh_pattern] = by_pattern.emplace(s.output.pattern, i);
      if (!fresh_pattern)
        r_.fail(node[i], child_path(scene_path, "output.pattern"),
                quoted_text(s.output.pattern, kPathShown) + " is also the pattern of " +
                    index_path(path, same->second) +
                    "; the scenes would overwrite each other's images (add {scene})");
    }
    return out;
  }

  SceneConfig scene(const YAML::Node &node, const std::string &path, size_t index) const {
    if (!node.IsMap()) r_.fail(node, path, "each scene must be a mapping (name:, width:, ...)");
    r_.check_map(node, path, kSceneKeys);
    SceneConfig s;
    if (index > 0) s.name = "scene" + std::to_string(index);
    optional_key(node, path, "name",
                 [&](const YAML::Node &n, const std::string &p) { s.name = scene_name(n, p); });
    optional_key(node, path, "width", [&](const YAML::Node &n, const std::string &p) {
      s.width = static_cast<int>(r_.read_int(n, p, 1, kMaxImageSize));
    });
    optional_key(node, path, "height", [&](const YAML::Node &n, const std::string &p) {
      s.height = static_cast<int>(r_.read_int(n, p, 1, kMaxImageSize));
    });
    optional_key(node, path, "background", [&](const YAML::Node &n, const std::string &p) {
      s.background = r_.read_rgb(n, p);
    });
    optional_key(node, path, "radius", [&](const YAML::Node &n, const std::string &p) {
      if (n.IsScalar() && n.Scalar() == "per_particle") {
        s.per_particle_radius = true;
        return;
      }
      double value = 0;
      if (!n.IsScalar() || !YAML::convert<double>::decode(n, value) || !std::isfinite(value) ||
          value <= 0)
        r_.fail(n, p,
                "must be a finite number > 0 or 'per_particle', got " +
                    (n.IsScalar() ? quoted_text(n.Scalar()) : std::string("a collection")));
      s.radius = value;
    });
    optional_key(node, path, "camera",
                 [&](const YAML::Node &n, const std::string &p) { s.camera = camera(n, p); });
    optional_key(node, path, "color",
                 [&](const YAML::Node &n, const std::string &p) { s.color = color(n, p); });
    optional_key(node, path, "output",
                 [&](const YAML::Node &n, const std::string &p) { s.output = output(n, p); });
    optional_key(node, path, "culling",
                 [&](const YAML::Node &n, const std::string &p) { s.culling = culling(n, p); });
    optional_key(node, path, "lod",
                 [&](const YAML::Node &n, const std::string &p) { s.lod = lod(n, p); });
    optional_key(node, path, "renderer", [&](const YAML::Node &n, const std::string &p) {
      s.renderer = read_enum<RendererChoice>(n, p);
    });
    optional_key(node, path, "cut_planes", [&](const YAML::Node &n, const std::string &p) {
      r_.check_sequence(n, p);
      for (size_t i = 0; i < n.size(); ++i) s.cuts.push_back(cut_plane(n[i], index_path(p, i)));
    });
    optional_key(node, path, "samples", [&](const YAML::Node &n, const std::string &p) {
      s.samples = std::stoi(r_.read_choice(n, p, {"1", "4", "16", "64"}));
      check_sample_frame(s, n, p);
    });
    read_depth_cues(node, path, &s);
    optional_key(node, path, "lighting",
                 [&](const YAML::Node &n, const std::string &p) { s.lighting = lighting(n, p); });
    optional_key(node, path, "opacity", [&](const YAML::Node &n, const std::string &p) {
      r_.check_sequence(n, p);
      if (n.size() == 0) r_.fail(n, p, "must list at least one opacity (omit it for opaque)");
      for (size_t i = 0; i < n.size(); ++i)
        s.opacity.push_back(r_.read_in_range(n[i], index_path(p, i), 0.0, true, 1.0, true));
    });
    // Seed 004's culling runs inside the CPU raster's pass only.
    if (s.culling.occlusion == OcclusionMode::kProbabilistic &&
        s.renderer == RendererChoice::kOpenGl)
      r_.fail(node["renderer"], child_path(path, "renderer"),
              "'opengl' cannot serve culling.occlusion 'probabilistic' (a renderer that cannot "
              "serve it); allowed with probabilistic: auto, cpu");
    optional_key(node, path, "style", [&](const YAML::Node &n, const std::string &p) {
      s.style = read_enum<SceneStyle>(n, p);
    });
    optional_key(node, path, "density",
                 [&](const YAML::Node &n, const std::string &p) { s.density = density(n, p); });
    if (s.style == SceneStyle::kDensity) check_density_scene(node, path, s);
    return s;
  }

  // A density image is a sum of smooth footprints with no surface: nothing to super-sample and
  // no depth for the screen-space cues to read, so those keys are refused rather than ignored.
  void check_density_scene(const YAML::Node &node, const std::string &path,
                           const SceneConfig &s) const {
    if (s.samples != 1)
      r_.fail(node["samples"], child_path(path, "samples"),
              "must be 1 with style: density (footprints are already smooth); allowed: 1");
    for (const char *cue : {"ambient_occlusion", "outline", "depth_cue"})
      if (node[cue].IsDefined())
        r_.fail(node[cue], child_path(path, cue),
                "needs style: spheres (a density image has no depth to cue)");
  }

  // A super-sampled frame must fit the documented limit: refused here, at lantern_open, rather
  // than failing an allocation mid-run.
  void check_sample_frame(const SceneConfig &s, const YAML::Node &node,
                          const std::string &path) const {
    const int64_t pixels = int64_t(s.width) * s.height * s.samples;
    if (s.samples == 1 || pixels <= kMaxSampleFramePixels) return;
    r_.fail(
        node, path,
        "scene " + quoted_text(s.name) + ": " + std::to_string(s.width) + " x " +
            std::to_string(s.height) + " at " + std::to_string(s.samples) +
            " samples needs a sample frame of " + std::to_string(pixels) + " pixels, " +
            std::to_string(pixels * 8) + " bytes (RGBA8 + float depth) per rank; the limit is " +
            std::to_string(kMaxSampleFramePixels) + " pixels (" +
            std::to_string(kMaxSampleFramePixels * 8) + " bytes): lower samples, width or height");
  }

  // The depth cues (issue 13): a section that is present turns its cue on, `{}` with defaults.
  void read_depth_cues(const YAML::Node &node, const std::string &path, SceneConfig *s) const {
    const auto present = [&](const std::string &key) {
      const YAML::Node n = node[key];
      return n.IsDefined() && (n.IsNull() || n.IsMap());
    };
    for (const char *key : {"ambient_occlusion", "outline", "depth_cue"}) {
      const YAML::Node n = node[key];
      if (n.IsDefined() && !n.IsNull() && !n.IsMap())
        r_.fail(n, child_path(path, key), "must be a mapping ({} for the defaults)");
    }
    if (present("ambient_occlusion"))
      s->ambient_occlusion =
          ambient_occlusion(node["ambient_occlusion"], child_path(path, "ambient_occlusion"));
    if (present("outline")) s->outline = outline(node["outline"], child_path(path, "outline"));
    if (present("depth_cue"))
      s->depth_cue = depth_cue(node["depth_cue"], child_path(path, "depth_cue"));
  }

  AmbientOcclusionConfig ambient_occlusion(const YAML::Node &node, const std::string &path) const {
    r_.check_map(node, path, kAmbientOcclusionKeys);
    AmbientOcclusionConfig a;
    a.enabled = true;
    optional_key(node, path, "method", [&](const YAML::Node &n, const std::string &p) {
      a.method = r_.read_choice(n, p, {"screen", "object"}) == "screen"
                     ? AmbientOcclusionMethod::kScreen
                     : AmbientOcclusionMethod::kObject;
    });
    optional_key(node, path, "radius", [&](const YAML::Node &n, const std::string &p) {
      a.radius = r_.read_in_range(n, p, 0.0, false, kInf, false);
    });
    optional_key(node, path, "samples", [&](const YAML::Node &n, const std::string &p) {
      a.samples = static_cast<int>(r_.read_int(n, p, 1, 64));
    });
    optional_key(node, path, "strength", [&](const YAML::Node &n, const std::string &p) {
      a.strength = r_.read_in_range(n, p, 0.0, true, 1.0, true);
    });
    return a;
  }

  OutlineConfig outline(const YAML::Node &node, const std::string &path) const {
    r_.check_map(node, path, kOutlineKeys);
    OutlineConfig o;
    o.enabled = true;
    optional_key(node, path, "width", [&](const YAML::Node &n, const std::string &p) {
      o.width = static_cast<int>(r_.read_int(n, p, 1, 16));
    });
    optional_key(node, path, "color",
                 [&](const YAML::Node &n, const std::string &p) { o.color = r_.read_rgb(n, p); });
    optional_key(node, path, "depth_threshold", [&](const YAML::Node &n, const std::string &p) {
      o.depth_threshold = r_.read_in_range(n, p, 0.0, true, kInf, false);
    });
    return o;
  }

  DepthCueConfig depth_cue(const YAML::Node &node, const std::string &path) const {
    r_.check_map(node, path, kDepthCueKeys);
    DepthCueConfig d;
    d.enabled = true;
    optional_key(node, path, "start", [&](const YAML::Node &n, const std::string &p) {
      if (n.IsScalar() && n.Scalar() == "auto") return;
      d.start = r_.read_in_range(n, p, 0.0, true, kInf, false);
    });
    optional_key(node, path, "end", [&](const YAML::Node &n, const std::string &p) {
      if (n.IsScalar() && n.Scalar() == "auto") return;
      d.end = r_.read_in_range(n, p, d.start.value_or(0.0), false, kInf, false);
    });
    optional_key(node, path, "color",
                 [&](const YAML::Node &n, const std::string &p) { d.color = r_.read_rgb(n, p); });
    return d;
  }

  // lighting: {...} (lighting.h); every key optional, absent = the default headlight's value.
  Lighting lighting(const YAML::Node &node, const std::string &path) const {
    if (!node.IsMap()) r_.fail(node, path, "must be a mapping ({} for the defaults)");
    r_.check_map(node, path, kLightingKeys);
    Lighting l;
    optional_key(node, path, "direction", [&](const YAML::Node &n, const std::string &p) {
      const std::array<double, 3> d = r_.read_vec3(n, p);
      const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      if (!(length > 0.0) || !std::isfinite(length))
        r_.fail(n, p,
                "must be a non-zero, finite vector [x, y, z] (camera-relative: x right, y up, "
                "z towards the viewer)");
      // [0, 0, 1] in any length is the headlight exactly, not a rounded neighbour of it.
      l.direction = {d[0] / length, d[1] / length, d[2] / length};
    });
    optional_key(node, path, "ambient", [&](const YAML::Node &n, const std::string &p) {
      l.ambient = r_.read_in_range(n, p, 0.0, true, 1.0, true);
    });
    optional_key(node, path, "diffuse", [&](const YAML::Node &n, const std::string &p) {
      l.diffuse = r_.read_in_range(n, p, 0.0, true, 1.0, true);
    });
    optional_key(node, path, "specular", [&](const YAML::Node &n, const std::string &p) {
      l.specular = r_.read_in_range(n, p, 0.0, true, 1.0, true);
    });
    optional_key(node, path, "shininess", [&](const YAML::Node &n, const std::string &p) {
      l.shininess = r_.read_in_range(n, p, kMinShininess, true, kMaxShininess, true);
    });
    return l;
  }

  // Names end up in file names ({scene}) and stats: keep them to portable file-name characters.
  std::string scene_name(const YAML::Node &node, const std::string &path) const {
    const std::string name = r_.read_string(node, path);
    for (const char c : name) {
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.')
        r_.fail(node, path,
                quoted_text(name) + " may contain only letters, digits, '_', '-' and '.'");
    }
    if (name == "." || name == "..") r_.fail(node, path, "'" + name + "' is not a usable name");
    return name;
  }

  // A configuration enum, by the names of its table (core/config/enum_names.h).
  template <typename E>
  E read_enum(const YAML::Node &node, const std::string &path) const {
    return *value_of<E>(r_.read_choice(node, path, names_of<E>()));
  }

  CameraConfig camera(const YAML::Node &node, const std::string &path) const {
    r_.check_map(node, path, kCameraKeys);
    CameraConfig c;
    optional_key(node, path, "projection", [&](const YAML::Node &n, const std::string &p) {
      c.projection = read_enum<Projection>(n, p);
    });
    optional_key(node, path, "fov", [&](const YAML::Node &n, const std::string &p) {
      c.fov_y = r_.read_in_range(n, p, 0.0, false, 180.0, false);
    });
    optional_key(node, path, "azimuth", [&](const YAML::Node &n, const std::string &p) {
      c.azimuth = r_.read_finite(n, p);
    });
    optional_key(node, path, "elevation", [&](const YAML::Node &n, const std::string &p) {
      c.elevation = r_.read_in_range(n, p, -90.0, true, 90.0, true);
    });
    optional_key(node, path, "zoom", [&](const YAML::Node &n, const std::string &p) {
      c.zoom = r_.read_in_range(n, p, 0.0, false, kInf, false);
    });
    optional_key(node, path, "position", [&](const YAML::Node &n, const std::string &p) {
      c.position = r_.read_vec3(n, p);
    });
    optional_key(node, path, "look_at", [&](const YAML::Node &n, const std::string &p) {
      if (!c.position)
        r_.fail(n, p, "look_at needs an explicit camera: set camera.position as well");
      c.look_at = r_.read_vec3(n, p);
      if (c.look_at == *c.position) r_.fail(n, p, "must differ from camera.position");
    });
    optional_key(node, path, "up", [&](const YAML::Node &n, const std::string &p) {
      c.up = r_.read_vec3(n, p);
      if (c.up == std::array<double, 3>{0, 0, 0}) r_.fail(n, p, "must not be the zero vector");
    });
    optional_key(node, path, "near", [&](const YAML::Node &n, const std::string &p) {
      c.near_plane = r_.read_in_range(n, p, 0.0, false, kInf, false);
    });
    optional_key(node, path, "far", [&](const YAML::Node &n, const std::string &p) {
      c.far_plane = r_.read_in_range(n, p, c.near_plane.value_or(0.0), false, kInf, false);
    });
    if (c.position && c.look_at == *c.position)  // look_at defaulted to the origin
      r_.fail(node["position"], child_path(path, "position"),
              "the explicit camera looks at look_at (default [0, 0, 0]); position must differ");
    return c;
  }

  ColorConfig color(const YAML::Node &node, const std::string &path) const {
    r_.check_map(node, path, kColorKeys);
    ColorConfig c;
    optional_key(node, path, "by", [&](const YAML::Node &n, const std::string &p) {
      c.by = read_enum<ColorBy>(n, p);
    });
    optional_key(node, path, "solid",
                 [&](const YAML::Node &n, const std::string &p) { c.solid = r_.read_rgb(n, p); });
    optional_key(node, path, "palette", [&](const YAML::Node &n, const std::string &p) {
      r_.check_sequence(n, p);
      if (n.size() == 0) r_.fail(n, p, "must list at least one color (omit it for the default)");
      for (size_t i = 0; i < n.size(); ++i)
        c.palette.push_back(r_.read_rgb(n[i], index_path(p, i)));
    });
    optional_key(node, path, "colormap", [&](const YAML::Node &n, const std::string &p) {
      c.colormap = r_.read_choice(n, p, kColormaps);
    });
    optional_key(node, path, "range", [&](const YAML::Node &n, const std::string &p) {
      if (n.IsScalar() && n.Scalar() == "auto") return;
      if (!n.IsSequence() || n.size() != 2)
        r_.fail(n, p, "must be 'auto' or [min, max] with min < max");
      const double lo = r_.read_finite(n[0], index_path(p, 0));
      const double hi = r_.read_finite(n[1], index_path(p, 1));
      if (!(lo < hi)) r_.fail(n, p, "must be 'auto' or [min, max] with min < max");
      c.range = std::array<double, 2>{lo, hi};
    });
    return c;
  }

  OutputConfig output(const YAML::Node &node, const std::string &path) const {
    r_.check_map(node, path, kOutputKeys);
    OutputConfig o;
    optional_key(node, path, "pattern", [&](const YAML::Node &n, const std::string &p) {
      o.pattern = r_.read_string(n, p);
      const Status problem = validate_pattern(o.pattern);
      if (!problem.ok()) r_.fail(n, p, quoted_text(o.pattern, kPathShown) + ": " + problem.message);
    });
    const std::optional<ImageFormat> from_extension = format_of_extension(o.pattern);
    bool format_given = false;
    optional_key(node, path, "format", [&](const YAML::Node &n, const std::string &p) {
      o.format = read_enum<ImageFormat>(n, p);
      if (from_extension && *from_extension != o.format)
        r_.fail(n, p,
                quoted_text(n.Scalar()) + " contradicts the extension of output.pattern " +
                    quoted_text(o.pattern, kPathShown));
      format_given = true;
    });
    if (!format_given) {
      if (!from_extension)
        r_.fail(node["pattern"], child_path(path, "pattern"),
                quoted_text(o.pattern, kPathShown) +
                    " has no image extension (.png, .jpg, .jpeg, .tif, .tiff, .exr); add one or "
                    "set output.format");
      o.format = *from_extension;
    }
    optional_key(node, path, "jpeg_quality", [&](const YAML::Node &n, const std::string &p) {
      o.jpeg_quality = static_cast<int>(r_.read_int(n, p, 1, 100));
    });
    optional_key(node, path, "compression_level", [&](const YAML::Node &n, const std::string &p) {
      o.compression_level = static_cast<int>(r_.read_int(n, p, 0, 9));
    });
    optional_key(node, path, "asynchronous", [&](const YAML::Node &n, const std::string &p) {
      o.asynchronous = r_.read_bool(n, p);
    });
    optional_key(node, path, "exr_color", [&](const YAML::Node &n, const std::string &p) {
      o.exr_half = r_.read_choice(n, p, {"half", "float"}) == "half";
    });
    return o;
  }

  static std::optional<ImageFormat> format_of_extension(const std::string &pattern) {
    const std::string extension = lower(std::filesystem::path(pattern).extension().string());
    if (extension.size() < 2) return std::nullopt;
    return value_of<ImageFormat>(extension.substr(1));
  }

  CullingConfig culling(const YAML::Node &node, const std::string &path) const {
    r_.check_map(node, path, kCullingKeys);
    CullingConfig c;
    optional_key(node, path, "frustum", [&](const YAML::Node &n, const std::string &p) {
      c.frustum = r_.read_bool(n, p);
    });
    optional_key(node, path, "occlusion", [&](const YAML::Node &n, const std::string &p) {
      c.occlusion = read_enum<OcclusionMode>(n, p);
    });
    optional_key(node, path, "nine_spheres_radius", [&](const YAML::Node &n, const std::string &p) {
      c.nine_spheres_radius = read_enum<NineSpheresRadius>(n, p);
    });
    ProbabilisticConfig &prob = c.probabilistic;
    optional_key(node, path, "confidence", [&](const YAML::Node &n, const std::string &p) {
      prob.confidence = r_.read_in_range(n, p, 0.0, false, 1.0, false);
    });
    optional_key(node, path, "probabilistic_budget",
                 [&](const YAML::Node &n, const std::string &p) {
                   prob.budget = static_cast<int>(r_.read_int(n, p, 1, 64));
                 });
    optional_key(node, path, "probabilistic_patience",
                 [&](const YAML::Node &n, const std::string &p) {
                   prob.patience = static_cast<int>(r_.read_int(n, p, 1, 64));
                 });
    return c;
  }

  LodConfig lod(const YAML::Node &node, const std::string &path) const {
    r_.check_map(node, path, kLodKeys);
    LodConfig l;
    optional_key(node, path, "budget", [&](const YAML::Node &n, const std::string &p) {
      l.budget = r_.read_int(n, p, 0, kMaxInt);
    });
    optional_key(node, path, "fraction", [&](const YAML::Node &n, const std::string &p) {
      l.fraction = r_.read_in_range(n, p, 0.0, false, 1.0, true);
    });
    optional_key(node, path, "min_pixels", [&](const YAML::Node &n, const std::string &p) {
      l.min_pixels = r_.read_in_range(n, p, 0.0, true, kInf, false);
    });
    optional_key(node, path, "point_path", [&](const YAML::Node &n, const std::string &p) {
      l.point_path = r_.read_bool(n, p);
    });
    optional_key(node, path, "select", [&](const YAML::Node &n, const std::string &p) {
      l.select = read_enum<LodSelect>(n, p);
    });
    return l;
  }

  // density: (style: density). A fixed range under the log transfer must be positive: log(0)
  // has no picture.
  DensityConfig density(const YAML::Node &node, const std::string &path) const {
    r_.check_map(node, path, kDensityKeys);
    DensityConfig d;
    optional_key(node, path, "transfer", [&](const YAML::Node &n, const std::string &p) {
      d.transfer = read_enum<DensityTransfer>(n, p);
    });
    optional_key(node, path, "colormap", [&](const YAML::Node &n, const std::string &p) {
      d.colormap = r_.read_choice(n, p, kColormaps);
    });
    optional_key(node, path, "range", [&](const YAML::Node &n, const std::string &p) {
      if (n.IsScalar() && n.Scalar() == "auto") return;
      if (!n.IsSequence() || n.size() != 2)
        r_.fail(n, p, "must be 'auto' or [lo, hi] with lo < hi");
      const double lo = r_.read_finite(n[0], index_path(p, 0));
      const double hi = r_.read_finite(n[1], index_path(p, 1));
      if (!(lo < hi)) r_.fail(n, p, "must be 'auto' or [lo, hi] with lo < hi");
      d.range = std::array<double, 2>{lo, hi};
    });
    if (d.transfer == DensityTransfer::kLog && d.range && (*d.range)[0] <= 0.0)
      r_.fail(node["range"], child_path(path, "range"),
              "transfer: log needs a range with lo > 0 (or 'auto'), got lo = " +
                  std::to_string((*d.range)[0]));
    return d;
  }

  CutPlane cut_plane(const YAML::Node &node, const std::string &path) const {
    if (!node.IsMap()) r_.fail(node, path, "each cut plane must be a mapping {normal, offset}");
    r_.check_map(node, path, kCutPlaneKeys);
    CutPlane c;
    optional_key(node, path, "normal", [&](const YAML::Node &n, const std::string &p) {
      c.normal = r_.read_vec3(n, p);
      if (c.normal == std::array<double, 3>{0, 0, 0}) r_.fail(n, p, "must not be the zero vector");
    });
    optional_key(node, path, "offset", [&](const YAML::Node &n, const std::string &p) {
      c.offset = r_.read_finite(n, p);
    });
    optional_key(node, path, "enabled", [&](const YAML::Node &n, const std::string &p) {
      c.enabled = r_.read_bool(n, p);
    });
    return c;
  }

  DumpConfig dump(const YAML::Node &node, const std::string &path) const {
    r_.check_map(node, path, kDumpKeys);
    DumpConfig d;
    d.enabled = true;
    optional_key(node, path, "enabled", [&](const YAML::Node &n, const std::string &p) {
      d.enabled = r_.read_bool(n, p);
    });
    optional_key(node, path, "file",
                 [&](const YAML::Node &n, const std::string &p) { d.file = r_.read_string(n, p); });
    optional_key(node, path, "schedule",
                 [&](const YAML::Node &n, const std::string &p) { d.schedule = schedule(n, p); });
    optional_key(node, path, "fields", [&](const YAML::Node &n, const std::string &p) {
      r_.check_sequence(n, p);
      for (size_t i = 0; i < n.size(); ++i) {
        const std::string field = r_.read_choice(n[i], index_path(p, i), kDumpFields);
        if (std::find(d.fields.begin(), d.fields.end(), field) != d.fields.end())
          r_.fail(n[i], index_path(p, i), "'" + field + "' is listed twice");
        d.fields.push_back(field);
      }
    });
    optional_key(node, path, "precision", [&](const YAML::Node &n, const std::string &p) {
      d.single_precision = r_.read_choice(n, p, {"float32", "float64"}) == "float32";
    });
    return d;
  }

  LammpsConfig lammps(const YAML::Node &node, const std::string &path) const {
    r_.check_map(node, path, kLammpsKeys);
    LammpsConfig l;
    optional_key(node, path, "fix", [&](const YAML::Node &n, const std::string &p) {
      l.fix = r_.read_string(n, p);
      if (l.fix.empty()) r_.fail(n, p, "must name a fix ID (omit the key for every fix external)");
    });
    optional_key(node, path, "scalar", [&](const YAML::Node &n, const std::string &p) {
      l.scalar = r_.read_string(n, p);
      if (l.scalar.empty()) r_.fail(n, p, "must name a per-atom quantity (c_ID, v_name, vx, ...)");
    });
    return l;
  }

  YamlReader r_;
};

bool is_inline_document(const std::string &s) {
  const size_t first = s.find_first_not_of(" \t");
  return s.find('\n') != std::string::npos || (first != std::string::npos && s[first] == '{');
}

// Reads the whole file. On failure kConfig (a configuration that cannot be read is a
// configuration error, LANTERN_ERROR_CONFIG in the C API) naming the file and the OS reason.
Status read_file(const std::string &path, std::string *text) {
  const auto unreadable = [&](const std::string &reason) {
    return Status(StatusCode::kConfig, "cannot read config file '" + path + "': " + reason);
  };
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return unreadable(std::strerror(EISDIR));
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) return unreadable(std::strerror(errno != 0 ? errno : ENOENT));
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return unreadable("read error");
  *text = buffer.str();
  return {};
}

}  // namespace

Status read_config_text(const std::string &path_or_document, std::string *text, std::string *path) {
  if (text == nullptr || path == nullptr)
    return {StatusCode::kNullArgument, "read_config_text: an output pointer is null"};
  if (is_inline_document(path_or_document)) {
    *text = path_or_document;
    path->clear();
    return {};
  }
  if (path_or_document.empty()) return {StatusCode::kConfig, "the configuration path is empty"};
  if (Status s = read_file(path_or_document, text); !s.ok()) return s;
  *path = path_or_document;
  return {};
}

Status load_config_text(const std::string &text, const std::string &source, Config *out) {
  if (out == nullptr)
    return {StatusCode::kNullArgument, "load_config: the output Config pointer is null"};
  // Every message may quote the document (yaml-cpp's too): never raw bytes to a terminal.
  const auto invalid = [](const std::string &message) {
    return Status(StatusCode::kConfig, escaped_text(message));
  };
  try {
    // All documents, so that a second one (after '---') is an error instead of silently ignored.
    const std::vector<YAML::Node> documents = YAML::LoadAll(text);
    if (documents.size() > 1) {
      const YAML::Mark mark = documents[1].Mark();
      return invalid(source + (mark.is_null() ? "" : " line " + std::to_string(mark.line + 1)) +
                     ": a second YAML document (after '---'); the configuration is one document: "
                     "merge the two or remove the '---'");
    }
    const YAML::Node root = documents.empty() ? YAML::Node() : documents.front();
    *out = Loader(source).load(root);
    return {};
  } catch (const ConfigError &e) {
    return invalid(e.what());
  } catch (const YAML::ParserException &e) {
    return invalid(source + " line " + std::to_string(e.mark.line + 1) + ", column " +
                   std::to_string(e.mark.column + 1) + ": malformed YAML: " + e.msg);
  } catch (const YAML::Exception &e) {
    return invalid(source + ": " + e.what());
  } catch (const std::exception &e) {
    return invalid(source + ": " + e.what());
  } catch (...) {
    return invalid(source + ": unexpected error while loading the configuration");
  }
}

Status load_config(const std::string &path_or_document, Config *out) {
  if (out == nullptr)
    return {StatusCode::kNullArgument, "load_config: the output Config pointer is null"};
  std::string text, path;
  if (Status s = read_config_text(path_or_document, &text, &path); !s.ok()) return s;
  return load_config_text(text, path.empty() ? "inline config" : path, out);
}

}  // namespace lantern
