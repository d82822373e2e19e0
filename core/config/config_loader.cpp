// The configuration's schema and its loader. Each section of the YAML document is one table
// (key_table.h): a key, the field it fills and the reader that checks its value, in the order the
// keys are read and listed in messages. Cross-key rules live in config_rules.cpp and appear in a
// table where they run.
//
// Adding a key: one entry in its section's table, one row in that section's table in
// config/README.md and one line in config/reference.yaml (tests/config/config_docs_test.cpp
// checks all three agree). A new section is a new Section<T> table, named by a key of its parent
// ({"movie", &OutputConfig::movie, kMovie}; a list of them: list_of(kKeyframe)).
#include "core/config/config_loader.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "core/color/colormap.h"
#include "core/color/colormap_file.h"
#include "core/common/quoted_text.h"
#include "core/config/config_file.h"
#include "core/config/config_rules.h"
#include "core/config/file_pattern.h"
#include "core/config/key_table.h"
#include "core/config/label_template.h"
#include "core/config/value_readers.h"
#include "core/config/yaml_guard.h"
#include "core/config/yaml_reader.h"

namespace lantern {

namespace {

using namespace value_readers;

// --- Readers of single keys that Lantern alone has -----------------------------------------

// Names end up in file names ({scene}) and stats: keep them to portable file-name characters.
std::string scene_name(const YamlReader &r, const YAML::Node &node, const std::string &path) {
  const std::string name = r.read_string(node, path);
  for (const char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.')
      r.fail(node, path, quoted_text(name) + " may contain only letters, digits, '_', '-' and '.'");
  }
  if (name == "." || name == "..") r.fail(node, path, "'" + name + "' is not a usable name");
  return name;
}

// The first scene is "scene" (SceneConfig's default), the others "scene1", "scene2", ...
void default_scene_name(SceneConfig &s, size_t index) {
  if (index > 0) s.name = "scene" + std::to_string(index);
}

// radius: a number for every particle, or per_particle (the published radius array).
void read_radius(const YamlReader &r, const YAML::Node &n, const std::string &p, SceneConfig &s) {
  if (n.IsScalar() && n.Scalar() == "per_particle") {
    s.per_particle_radius = true;
    return;
  }
  double value = 0;
  if (!n.IsScalar() || !YAML::convert<double>::decode(n, value) || !std::isfinite(value) ||
      value <= 0)
    r.fail(n, p,
           "must be a finite number > 0 or 'per_particle', got " +
               (n.IsScalar() ? quoted_text(n.Scalar()) : std::string("a collection")));
  s.radius = value;
}

// background: [r, g, b], or transparent (alpha 0 where nothing is drawn).
void read_background(const YamlReader &r, const YAML::Node &n, const std::string &p,
                     SceneConfig &s) {
  if (n.IsScalar() && n.Scalar() == "transparent") {
    s.transparent_background = true;
    return;
  }
  if (n.IsScalar())
    r.fail(n, p,
           "must be a color [r, g, b] with components in [0, 1] or 'transparent', got " +
               quoted_text(n.Scalar()));
  s.background = r.read_rgb(n, p);
}

std::string image_pattern(const YamlReader &r, const YAML::Node &n, const std::string &p) {
  const std::string pattern = r.read_string(n, p);
  const Status problem = validate_pattern(pattern);
  if (!problem.ok()) r.fail(n, p, quoted_text(pattern, kPathShown) + ": " + problem.message);
  return pattern;
}

// lighting.direction: normalised on reading.
std::array<double, 3> light_direction(const YamlReader &r, const YAML::Node &n,
                                      const std::string &p) {
  const std::array<double, 3> d = r.read_vec3(n, p);
  const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!(length > 0.0) || !std::isfinite(length))
    r.fail(n, p,
           "must be a non-zero, finite vector [x, y, z] (camera-relative: x right, y up, "
           "z towards the viewer)");
  // [0, 0, 1] in any length is the headlight exactly, not a rounded neighbour of it.
  return {d[0] / length, d[1] / length, d[2] / length};
}

// colormap: a name, a list of control points [[r,g,b], ...] or {file: PATH} (colormap_file.h);
// a list or a file makes the name "custom".
void read_colormap(const YamlReader &r, const YAML::Node &n, const std::string &p, ColorConfig &c) {
  if (n.IsScalar()) {
    c.colormap = r.read_choice(n, p, Colormap::names());
    return;
  }
  c.colormap = "custom";
  if (n.IsSequence()) {
    if (n.size() < 2 || n.size() > kMaxColormapColors)
      r.fail(n, p,
             "a custom colormap lists 2 to " + std::to_string(kMaxColormapColors) +
                 " colors [[r,g,b], ...] (components in [0, 1]), got " + std::to_string(n.size()));
    for (size_t i = 0; i < n.size(); ++i)
      c.colormap_colors.push_back(r.read_rgb(n[i], index_path(p, i)));
    return;
  }
  if (!n.IsMap()) r.fail(n, p, "must be a colormap name, a list [[r,g,b], ...] or {file: PATH}");
  r.check_map(n, p, {"file"});
  if (!n["file"].IsDefined()) r.fail(n, p, "{file: PATH} needs the key 'file'");
  const std::string file = r.read_string(n["file"], child_path(p, "file"));
  const Status read = read_colormap_file(file, &c.colormap_colors);
  if (!read.ok()) r.fail(n["file"], child_path(p, "file"), read.message);
}

// color.range: 'auto' (= {auto: frame}), {auto: frame | first | running} (color_range.h) or a
// fixed [min, max].
void read_color_range(const YamlReader &r, const YAML::Node &n, const std::string &p,
                      ColorConfig &c) {
  if (n.IsMap()) {
    r.check_map(n, p, {"auto"});
    if (!n["auto"].IsDefined()) r.fail(n, p, "must be {auto: frame | first | running}");
    c.auto_range = one_of<AutoRange>()(r, n["auto"], child_path(p, "auto"));
    return;
  }
  if (!(n.IsScalar() && n.Scalar() == "auto") && !(n.IsSequence() && n.size() == 2))
    r.fail(n, p, "must be 'auto', {auto: frame | first | running} or [min, max] with min < max");
  c.range = auto_or_range("min", "max")(r, n, p);
}

// output.movie.file: one file for the whole run, with a movie container's extension.
std::string movie_file(const YamlReader &r, const YAML::Node &n, const std::string &p) {
  const std::string file = image_pattern(r, n, p);
  if (expand_pattern(file, 0, "") != expand_pattern(file, 1, ""))
    r.fail(n, p,
           quoted_text(file, kPathShown) +
               ": a movie is one file for the whole run; {step} has no place in its name");
  std::string extension = std::filesystem::path(file).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (extension != ".mp4" && extension != ".mov" && extension != ".mkv" && extension != ".webm")
    r.fail(n, p,
           quoted_text(file, kPathShown) +
               " needs a movie extension: .mp4, .mov (fragmented MPEG-4), .mkv (Matroska) or "
               ".webm");
  return file;
}

// Overlay positions: a corner's name, or [x, y], the overlay's top-left pixel from the image's
// top-left corner.
OverlayPlace overlay_place(const YamlReader &r, const YAML::Node &n, const std::string &p) {
  OverlayPlace place;
  if (n.IsSequence()) {
    if (n.size() != 2)
      r.fail(n, p, "must be a corner (top_left, top_right, bottom_left, bottom_right) or [x, y]");
    place.at = std::array<int, 2>{int(r.read_int(n[0], index_path(p, 0), 0, kMaxImageSize)),
                                  int(r.read_int(n[1], index_path(p, 1), 0, kMaxImageSize))};
    return place;
  }
  place.corner = one_of<OverlayCorner>()(r, n, p);
  return place;
}

// labels[].text: a template whose fields are checked now (label_template.h).
std::string label_text(const YamlReader &r, const YAML::Node &n, const std::string &p) {
  const std::string text = r.read_string(n, p);
  const Status problem = validate_label_template(text);
  if (!problem.ok()) r.fail(n, p, quoted_text(text) + ": " + problem.message);
  return text;
}

const std::vector<std::string> kDumpFields = {"position", "type", "scalar", "radius", "id"};

// ambient_occlusion, outline, depth_cue: a section that is present turns its cue on; `outline:`
// or `outline: {}` with the defaults.
constexpr SectionShape kCue{"must be a mapping ({} for the defaults)", true};

// --- The tables, innermost first ----------------------------------------------------------

const Section<Schedule> kSchedule({
    {"every", &Schedule::every, integer(0, kMaxInt)},
    {"start", &Schedule::start, integer(0, kMaxInt)},
    {"steps", &Schedule::steps,
     sorted_set_of(list_of(integer(0, kMaxInt),
                           "must list at least one step (omit it for every step)"))},
});

// camera.path[i]: `step` is required; the other keys carry over (camera_path_is_ordered).
const Section<CameraKeyframe> kKeyframe(
    {
        rule(keyframe_has_step),
        // Up to 2^53: the path places keyframes in double precision, where two larger steps
        // could round to one (a zero interval, a NaN camera blamed on the particles).
        {"step", &CameraKeyframe::step, integer(0, int64_t(1) << 53)},
        {"azimuth", &CameraKeyframe::azimuth, finite()},
        {"elevation", &CameraKeyframe::elevation, number_in('[', -90, 90, ']')},
        {"zoom", &CameraKeyframe::zoom, above(0)},
    },
    {"each keyframe must be a mapping {step, azimuth, elevation, zoom}"});

const Section<CameraOrbit> kOrbit(
    {
        rule(orbit_has_rate),
        {"degrees_per_step", &CameraOrbit::degrees_per_step, number_in('[', -360, 360, ']')},
    },
    {"must be a mapping {degrees_per_step: d}"}, &CameraOrbit::enabled);

const Section<CameraConfig> kCamera({
    {"projection", &CameraConfig::projection, one_of<Projection>()},
    {"fov", &CameraConfig::fov_y, number_in('(', 0, 180, ')')},
    {"azimuth", &CameraConfig::azimuth, finite()},
    {"elevation", &CameraConfig::elevation, number_in('[', -90, 90, ']')},
    {"zoom", &CameraConfig::zoom, above(0)},
    {"position", &CameraConfig::position, vec3()},
    {"look_at", read_look_at},
    {"up", &CameraConfig::up, nonzero_vec3()},
    {"near", &CameraConfig::near_plane, above(0)},
    {"far", read_far},
    rule(camera_looks_away),
    {"path", &CameraConfig::path, list_of(kKeyframe)},
    {"orbit", &CameraConfig::orbit, kOrbit},
    rule(camera_path_is_ordered),
});

const Section<ColorConfig> kColor({
    {"by", &ColorConfig::by, one_of<ColorBy>()},
    {"solid", &ColorConfig::solid, rgb()},
    {"palette", &ColorConfig::palette,
     list_of(rgb(), "must list at least one color (omit it for the default)")},
    {"colormap", read_colormap},
    {"range", read_color_range},
    {"reverse", &ColorConfig::reverse, boolean()},
});

// output.movie: codec names and quality ranges are checked against this build's encoders when
// the context opens (core/output/movie/movie_encoder.h).
const Section<MovieConfig> kMovie(
    {
        rule(movie_has_file),
        {"file", &MovieConfig::file, movie_file},
        {"fps", &MovieConfig::fps, number_in('(', 0, 1000, ']')},
        {"codec", &MovieConfig::codec, text()},
        {"quality", &MovieConfig::quality, integer(0, 63)},
        {"lossless", &MovieConfig::lossless, boolean()},
        {"queue", &MovieConfig::queue, integer(1, 256)},
        {"when_behind", &MovieConfig::when_behind, one_of<MovieWhenBehind>()},
        {"threads", &MovieConfig::threads, integer(1, 16)},
        rule(lossless_has_no_quality),
    },
    {"must be a mapping {file: 'out/{scene}.mp4', ...}"}, &MovieConfig::enabled);

const Section<OutputConfig> kOutput({
    {"pattern", &OutputConfig::pattern, image_pattern},
    {"format", &OutputConfig::format, one_of<ImageFormat>()},
    rule(format_agrees_with_pattern),
    {"jpeg_quality", &OutputConfig::jpeg_quality, integer(1, 100)},
    {"compression_level", &OutputConfig::compression_level, integer(0, 9)},
    {"asynchronous", &OutputConfig::asynchronous, boolean()},
    {"exr_color", &OutputConfig::exr_half, one_of<bool>({{"half", true}, {"float", false}})},
    {"movie", &OutputConfig::movie, kMovie},
    rule(movie_replaces_images),
});

const Section<CullingConfig> kCulling({
    {"frustum", &CullingConfig::frustum, boolean()},
    {"occlusion", &CullingConfig::occlusion, one_of<OcclusionMode>()},
    {"nine_spheres_radius", &CullingConfig::nine_spheres_radius, one_of<NineSpheresRadius>()},
    {"confidence", member(&CullingConfig::probabilistic, &ProbabilisticConfig::confidence),
     number_in('(', 0, 1, ')')},
    {"probabilistic_budget", member(&CullingConfig::probabilistic, &ProbabilisticConfig::budget),
     integer(1, 64)},
    {"probabilistic_patience",
     member(&CullingConfig::probabilistic, &ProbabilisticConfig::patience), integer(1, 64)},
});

const Section<LodConfig> kLod({
    {"budget", &LodConfig::budget, integer(0, kMaxInt)},
    {"fraction", &LodConfig::fraction, number_in('(', 0, 1, ']')},
    {"min_pixels", &LodConfig::min_pixels, at_least(0)},
    {"point_path", &LodConfig::point_path, boolean()},
    {"select", &LodConfig::select, one_of<LodSelect>()},
});

const Section<CutPlane> kCutPlane(
    {
        {"normal", &CutPlane::normal, nonzero_vec3()},
        {"offset", &CutPlane::offset, finite()},
        {"enabled", &CutPlane::enabled, boolean()},
    },
    {"each cut plane must be a mapping {normal, offset}"});

const Section<AmbientOcclusionConfig> kAmbientOcclusion(
    {
        {"method", &AmbientOcclusionConfig::method,
         one_of<AmbientOcclusionMethod>({{"screen", AmbientOcclusionMethod::kScreen},
                                         {"object", AmbientOcclusionMethod::kObject}})},
        {"radius", &AmbientOcclusionConfig::radius, above(0)},
        {"samples", &AmbientOcclusionConfig::samples, integer(1, 64)},
        {"strength", &AmbientOcclusionConfig::strength, number_in('[', 0, 1, ']')},
        {"resolution", &AmbientOcclusionConfig::resolution,
         one_of<AoResolution>({{"half", AoResolution::kHalf}, {"full", AoResolution::kFull}})},
        {"max_nodes", &AmbientOcclusionConfig::max_nodes, integer(64, kLargestAoMaxNodes)},
    },
    kCue, &AmbientOcclusionConfig::enabled);

const Section<OutlineConfig> kOutline(
    {
        {"width", &OutlineConfig::width, integer(1, 16)},
        {"color", &OutlineConfig::color, rgb()},
        {"depth_threshold", &OutlineConfig::depth_threshold, at_least(0)},
    },
    kCue, &OutlineConfig::enabled);

const Section<DepthCueConfig> kDepthCue(
    {
        {"start", &DepthCueConfig::start, default_if("auto", at_least(0))},
        {"end", read_cue_end},
        {"color", &DepthCueConfig::color, rgb()},
    },
    kCue, &DepthCueConfig::enabled);

const Section<DensityConfig> kDensity({
    {"transfer", &DensityConfig::transfer, one_of<DensityTransfer>()},
    {"range", &DensityConfig::range, auto_or_range("lo", "hi")},
    {"colormap", &DensityConfig::colormap, one_of(Colormap::names())},
    rule(log_range_is_positive),
});

const Section<Lighting> kLighting(
    {
        {"direction", &Lighting::direction, light_direction},
        {"ambient", &Lighting::ambient, number_in('[', 0, 1, ']')},
        {"diffuse", &Lighting::diffuse, number_in('[', 0, 1, ']')},
        {"specular", &Lighting::specular, number_in('[', 0, 1, ']')},
        {"shininess", &Lighting::shininess, number_in('[', kMinShininess, kMaxShininess, ']')},
    },
    {"must be a mapping ({} for the defaults)"});

const Section<BondsConfig> kBonds(
    {
        {"radius", &BondsConfig::radius, above(0)},
        {"color", &BondsConfig::color, one_of<BondColorBy>()},
        {"solid", &BondsConfig::solid, rgb()},
        {"palette", &BondsConfig::palette,
         list_of(rgb(), "must list at least one color (omit it for the default)")},
    },
    kCue, &BondsConfig::enabled);
const Section<LabelConfig> kLabel(
    {
        rule(label_has_text),
        {"text", &LabelConfig::text, label_text},
        {"position", &LabelConfig::position, overlay_place},
        {"size", &LabelConfig::size, integer(4, 512)},
        {"color", &LabelConfig::color, rgb()},
    },
    {"each label must be a mapping {text: 'step {step}', ...}"});

const Section<LegendConfig> kLegend(
    {
        {"position", &LegendConfig::position, overlay_place},
        {"length", &LegendConfig::length, default_if("auto", integer(16, kMaxImageSize))},
        {"width", &LegendConfig::width, integer(2, 1024)},
        {"font_size", &LegendConfig::font_size, integer(4, 512)},
        {"color", &LegendConfig::color, rgb()},
        {"title", &LegendConfig::title, text()},
        {"ticks", &LegendConfig::ticks, integer(2, 20)},
        {"type_names", &LegendConfig::type_names,
         list_of(text(), "must list at least one name (type 0 first)")},
    },
    kCue, &LegendConfig::enabled);

const Section<BoxOverlayConfig> kBoxOverlay(
    {
        {"color", &BoxOverlayConfig::color, rgb()},
        {"width", &BoxOverlayConfig::width, number_in('(', 0, 16, ']')},
    },
    kCue, &BoxOverlayConfig::enabled);

const Section<AxesConfig> kAxes(
    {
        {"position", &AxesConfig::position, overlay_place},
        {"size", &AxesConfig::size, integer(16, 1024)},
        {"font_size", &AxesConfig::font_size, integer(4, 512)},
    },
    kCue, &AxesConfig::enabled);

const Section<SceneConfig> kScene(
    {
        {"name", &SceneConfig::name, scene_name},
        {"width", &SceneConfig::width, integer(1, kMaxImageSize)},
        {"height", &SceneConfig::height, integer(1, kMaxImageSize)},
        {"background", read_background},
        {"radius", read_radius},
        {"camera", &SceneConfig::camera, kCamera},
        {"color", &SceneConfig::color, kColor},
        {"output", &SceneConfig::output, kOutput},
        {"culling", &SceneConfig::culling, kCulling},
        {"lod", &SceneConfig::lod, kLod},
        {"cut_planes", &SceneConfig::cuts, list_of(kCutPlane)},
        {"renderer", &SceneConfig::renderer, one_of<RendererChoice>()},
        {"samples", &SceneConfig::samples,
         one_of<int>({{"1", 1}, {"4", 4}, {"16", 16}, {"64", 64}})},
        rule(sample_frame_fits),
        {"ambient_occlusion", &SceneConfig::ambient_occlusion, kAmbientOcclusion},
        {"budget_ms", &SceneConfig::budget_ms, above(0)},
        {"outline", &SceneConfig::outline, kOutline},
        {"depth_cue", &SceneConfig::depth_cue, kDepthCue},
        {"style", &SceneConfig::style, one_of<SceneStyle>()},
        {"density", &SceneConfig::density, kDensity},
        {"opacity", &SceneConfig::opacity,
         list_of(number_in('[', 0, 1, ']'), "must list at least one opacity (omit it for opaque)")},
        {"lighting", &SceneConfig::lighting, kLighting},
        {"bonds", &SceneConfig::bonds, kBonds},
        {"labels", &SceneConfig::labels, list_of(kLabel)},
        {"legend", &SceneConfig::legend, kLegend},
        {"box", &SceneConfig::box, kBoxOverlay},
        {"axes", &SceneConfig::axes, kAxes},
        {"font", &SceneConfig::font, text()},
        rule(legend_has_colors),
        rule(renderer_serves_occlusion),
        rule(density_scene_has_no_depth),
        rule(transparent_output_keeps_alpha),
    },
    {"each scene must be a mapping (name:, width:, ...)"});

const Section<DumpConfig> kDump(
    {
        {"enabled", &DumpConfig::enabled, boolean()},
        {"file", &DumpConfig::file, text()},
        {"schedule", &DumpConfig::schedule, kSchedule},
        {"fields", &DumpConfig::fields, distinct_list_of(one_of(kDumpFields))},
        {"precision", &DumpConfig::single_precision,
         one_of<bool>({{"float32", true}, {"float64", false}})},
        {"mode", &DumpConfig::mode, one_of<DumpMode>()},
    },
    {}, &DumpConfig::enabled);

const Section<LammpsConfig> kLammps({
    {"fix", &LammpsConfig::fix, text()},
    {"scalar", &LammpsConfig::scalar, text()},
});

const Section<Config> kTop(
    {
        {"schedule", &Config::schedule, kSchedule},
        {"scenes", &Config::scenes, list_of(kScene, default_scene_name)},
        rule(scenes_are_distinct),
        // An empty string is the documented way to write "no stats".
        {"stats", &Config::stats_file, default_if("", text())},
        {"verbose", &Config::verbose, boolean()},
        {"dump", &Config::dump, kDump},
        {"gl", &Config::gl, one_of<GlBackend>()},
        {"egl_device", &Config::egl_device, default_if("auto", integer(0, 1023))},
        {"lammps", &Config::lammps, kLammps},
        {"watch", &Config::watch, boolean()},
        // threads: 'auto' keeps 0, resolved per process (core/common/rank_threads.h).
        {"threads", &Config::threads, default_if("auto", integer(1, 1024))},
        {"budget_percent", &Config::budget_percent, number_in('(', 0, 100, ']')},
        rule(config_has_work),
    },
    {"the configuration must be a mapping with keys (schedule, scenes, ...)", true});

// --- The schema, walked from the top ------------------------------------------------------

// Each section once (dump.schedule is the top level's schedule), parents before children.
void collect_sections(const Schema &section, const std::string &label, const std::string &prefix,
                      std::set<const Schema *> *seen, std::vector<ConfigSection> *out) {
  if (!seen->insert(&section).second) return;
  ConfigSection entry{label, {}};
  for (const Schema::Key &key : section.keys()) entry.keys.push_back(key.name);
  out->push_back(entry);
  for (const Schema::Key &key : section.keys()) {
    if (key.section == nullptr) continue;
    const std::string child = prefix + key.name + (key.list ? "[]" : "");
    collect_sections(*key.section, child, child + ".", seen, out);
  }
}

// key -> the sections it belongs to, for "'azimuth' is a key of scenes[].camera".
const std::map<std::string, std::vector<std::string>> &key_homes() {
  static const std::map<std::string, std::vector<std::string>> homes = [] {
    std::map<std::string, std::vector<std::string>> h;
    for (const ConfigSection &section : config_sections())
      for (const std::string &key : section.keys) h[key].push_back(section.label);
    return h;
  }();
  return homes;
}

bool is_inline_document(const std::string &s) {
  const size_t first = s.find_first_not_of(" \t");
  return s.find('\n') != std::string::npos || (first != std::string::npos && s[first] == '{');
}

// Reads the whole file (config_file.h). On failure kConfig (a configuration that cannot be read
// is a configuration error, LANTERN_ERROR_CONFIG in the C API) naming the file and the reason.
Status read_file(const std::string &path, std::string *text) {
  if (const std::string why = read_config_file(path, text); !why.empty())
    return {StatusCode::kConfig, "cannot read config file '" + path + "': " + why};
  return {};
}

}  // namespace

std::vector<ConfigSection> config_sections() {
  std::vector<ConfigSection> sections;
  std::set<const Schema *> seen;
  collect_sections(kTop, "the top level", "", &seen, &sections);
  return sections;
}

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
    if (const std::string loop = check_yaml_text(text); !loop.empty())
      return invalid(source + " " + loop);
    // All documents, so that a second one (after '---') is an error instead of silently ignored.
    const std::vector<YAML::Node> documents = YAML::LoadAll(text);
    if (documents.size() > 1) {
      const YAML::Mark mark = documents[1].Mark();
      return invalid(source + (mark.is_null() ? "" : " line " + std::to_string(mark.line + 1)) +
                     ": a second YAML document (after '---'); the configuration is one document: "
                     "merge the two or remove the '---'");
    }
    const YAML::Node root = documents.empty() ? YAML::Node() : documents.front();
    YamlReader reader(source);
    reader.set_key_homes(key_homes());
    *out = kTop(reader, root, "");
    return {};
  } catch (const ConfigError &e) {
    return invalid(e.what());
  } catch (const YAML::ParserException &e) {
    const std::string explained = explain_yaml_error(text, e.mark, e.msg);
    return invalid(source + " line " + std::to_string(e.mark.line + 1) + ", column " +
                   std::to_string(e.mark.column + 1) +
                   ": malformed YAML: " + (explained.empty() ? e.msg : explained));
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
