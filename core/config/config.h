// The run configuration: what the YAML file says, validated and with defaults filled in.
//
// load_config() (config_loader.h) turns YAML into these structs; nothing else in Lantern reads
// YAML. Every field here has its YAML key in a comment; README.md's configuration reference
// lists the same keys. Units: lengths are in the simulation's units, angles in degrees.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/config/lighting.h"

namespace lantern {

// Which steps render (`schedule:`). A step renders if it is in `steps`, or if every > 0 and
// step >= start and (step - start) % every == 0. With neither key, every step renders.
struct Schedule {
  int64_t every = 0;           // every: N
  int64_t start = 0;           // start: first step of the `every` cadence
  std::vector<int64_t> steps;  // steps: [0, 100, 250]
  bool due(int64_t step) const;
};

enum class Projection { kPerspective, kOrthographic };

// camera.path[i]: the automatic camera at one step. A key a keyframe leaves out carries the
// previous keyframe's value (the first keyframe's: the camera's own azimuth/elevation/zoom), so
// after loading every value is set. Between keyframes the camera moves smoothly
// (core/camera/camera_path.h).
struct CameraKeyframe {
  int64_t step = 0;                 // step: the simulation step of this view, >= 0 (required)
  std::optional<double> azimuth;    // azimuth: degrees, as the camera's; the difference to the
                                    // previous keyframe is the turn taken (|difference| < 360)
  std::optional<double> elevation;  // elevation: degrees in [-90, 90]
  std::optional<double> zoom;       // zoom: > 0
};

// camera.orbit: the short form of a path: the automatic camera turns about the up axis by
// degrees_per_step every step, from the camera's azimuth at step 0.
struct CameraOrbit {
  bool enabled = false;           // the section is present
  double degrees_per_step = 0.0;  // degrees_per_step: in [-360, 360]
};

// camera: either automatic (fit to the global particle bounds, then azimuth/elevation/zoom)
// or explicit (position + look_at + up). Giving `position` switches to explicit. `path` or
// `orbit` move the automatic camera with the step.
struct CameraConfig {
  Projection projection = Projection::kPerspective;  // projection: perspective | orthographic
  double fov_y = 30.0;                               // fov: vertical field of view, degrees
  double azimuth = 30.0;    // azimuth: degrees about the up axis, from +x towards +y
  double elevation = 20.0;  // elevation: degrees above the horizontal plane
  double zoom = 1.0;        // zoom: > 1 moves closer / magnifies
  std::optional<std::array<double, 3>> position;  // position: [x, y, z]
  std::array<double, 3> look_at{0, 0, 0};         // look_at: [x, y, z] (explicit camera only)
  std::array<double, 3> up{0, 0, 1};              // up: [x, y, z]
  std::optional<double> near_plane;               // near / far: clip distances; auto by default
  std::optional<double> far_plane;
  std::vector<CameraKeyframe> path;  // path: [{step, azimuth, elevation, zoom}, ...], by step
  CameraOrbit orbit;                 // orbit: {degrees_per_step: d}
  bool moves() const { return !path.empty() || orbit.enabled; }
};

enum class ColorBy { kSolid, kType, kScalar };

// range: auto re-fits the scalar range every frame (frame); {auto: first} keeps the range of the
// first rendered frame that had one; {auto: running} the union of every frame's range so far.
// The frame ranges are reduced over ranks, so each mode is rank-invariant.
enum class AutoRange { kFrame, kFirst, kRunning };

struct ColorConfig {
  ColorBy by = ColorBy::kType;                 // by: solid | type | scalar
  std::array<double, 3> solid{0.8, 0.8, 0.8};  // solid: [r, g, b] in [0, 1]
  std::vector<std::array<double, 3>> palette;  // palette: [[r,g,b], ...]; empty = built-in
  // colormap: a name of Colormap::names() (core/color/colormap.h), or a custom map: a list
  // [[r,g,b], ...] or {file: PATH}; then the name is "custom" and colormap_colors holds the
  // control points (evenly spaced, components in [0, 1]).
  std::string colormap = "viridis";
  std::vector<std::array<double, 3>> colormap_colors;
  bool reverse = false;                        // reverse: run the colormap from its high end
  std::optional<std::array<double, 2>> range;  // range: [min, max]; absent = auto (global)
  AutoRange auto_range = AutoRange::kFrame;    // range: auto | {auto: frame | first | running}
};

enum class ImageFormat { kPng, kJpeg, kTiff, kExr };

// movie: when a frame arrives while `queue` frames already wait for the encoder. drop: the frame
// is left out of the movie (counted in the stats line; the step never waits); wait: the step
// waits for the encoder (the stats line says how long).
enum class MovieWhenBehind { kDrop, kWait };

// output.movie: one movie file per scene, every rendered frame encoded on rank 0 by a background
// thread (core/output/movie/movie_writer.h) through FFmpeg's libraries.
struct MovieConfig {
  bool enabled = false;  // the section is present
  // file: the movie's path; {scene} is the scene name. The extension picks the container: .mp4
  // and .mov (fragmented), .mkv (Matroska), .webm.
  std::string file;
  double fps = 24.0;           // fps: frames per second of the movie, (0, 1000]
  std::string codec = "auto";  // codec: auto | h264 | hevc | vp9 | av1 | ffv1
  // quality: the codec's constant-quality value (CRF: lower is better; h264 and hevc 0..51,
  // vp9 and av1 0..63); absent = the codec's default. Not with ffv1 or lossless.
  std::optional<int> quality;
  bool lossless = false;  // lossless: RGB frames, bit-exact (h264, hevc, vp9; ffv1 always is)
  int queue = 8;          // queue: frames that may wait for the encoder, 1..256
  MovieWhenBehind when_behind = MovieWhenBehind::kDrop;  // when_behind: drop | wait
  int threads = 1;  // threads: the encoder's threads, 1..16 (it shares rank 0's cores)
  bool operator==(const MovieConfig &o) const {
    return enabled == o.enabled && file == o.file && fps == o.fps && codec == o.codec &&
           quality == o.quality && lossless == o.lossless && queue == o.queue &&
           when_behind == o.when_behind && threads == o.threads;
  }
  bool operator!=(const MovieConfig &o) const { return !(*this == o); }
};

struct OutputConfig {
  std::string pattern = "lantern_{step:06d}.png";  // pattern: file name with {step} / {step:06d}
  // false when the section has a movie but no pattern: then no image files are written.
  bool images = true;
  MovieConfig movie;                       // movie: {...}
  ImageFormat format = ImageFormat::kPng;  // format: png|jpeg|tiff|exr (default: from pattern)
  int jpeg_quality = 95;                   // jpeg_quality: 1..100
  // compression_level: zlib level 0..9 of PNG and TIFF. 1 (fastest) by default: in situ, the
  // encoder's time is the simulation's; level 6 makes files ~10% smaller at 2-2.6x the time.
  int compression_level = 1;
  // asynchronous: encode and write on a background thread (background_image_writer.h); the
  // step returns after rendering and compositing, the file lands up to one scheduled step later
  // (and at lantern_close). Off by default: then the file exists when lantern_execute returns.
  bool asynchronous = false;
  bool exr_half = true;  // exr_color: half | float  (pixel type of the EXR R,G,B,A channels;
                         // the Z channel is always float)
};

// renderer: what draws the spheres. opengl: the GL impostor renderer (OSMesa). cpu: the CPU
// ray caster (cpu_sphere_raster.h), fused with hzb occlusion culling; it serves scenes whose
// occlusion mode is hzb or none. auto: cpu where occlusion runs as hzb and spheres are small
// on screen (where it measured faster), opengl elsewhere.
enum class RendererChoice { kAuto, kOpenGl, kCpu };

// probabilistic: Ibrahim et al.'s confidence-map culling (core/culling/probabilistic/); an
// approximate mode served by the CPU raster only, never chosen by auto.
enum class OcclusionMode { kAuto, kNone, kNineSpheres, kNineSpheresSorted, kHzb, kProbabilistic };

// The radius the nine-spheres rule compares (a sphere is hidden only by nearer spheres that are
// not smaller). world: the drawn radius, as the nine-spheres paper states the rule. equivalent: the
// equivalent radius of the nine-spheres paper's conference version, the radius of the sphere moved
// towards the eye onto the near plane and scaled to keep its projected size (r * near / depth in
// perspective, r in orthographic), so a near small sphere can hide a far large one that looks
// smaller on screen.
enum class NineSpheresRadius { kWorld, kEquivalent };

// Ibrahim et al.'s probabilistic occlusion culling (occlusion: probabilistic), culling.* keys.
struct ProbabilisticConfig {
  double confidence = 0.95;  // confidence: C_occ in (0, 1), occluded-class threshold
  int budget = 2;            // probabilistic_budget: occluder meshlets sampled per node per pass
  int patience = 3;          // probabilistic_patience: converged when no class changed this long
  // No YAML key (lantern-bench only): accept samples by a fair coin instead of eq. 21, the
  // paper's "random 50%" baseline of Table 4.
  bool random_acceptance = false;
  // No YAML key (lantern-bench only): converged when at most this share of the open meshlets
  // changed class; 0 is Ibrahim et al. 2022, §5.3 to the letter ("no meshlet changes"). See
  // probabilistic_culler.h for why the default tolerates 1%.
  double quiet_share = 0.01;
};

// culling: which particles are skipped before drawing, and how
struct CullingConfig {
  bool frustum = true;  // frustum: true|false
  OcclusionMode occlusion =
      OcclusionMode::kAuto;  // occlusion:
                             // auto|none|nine_spheres|nine_spheres_sorted|hzb|probabilistic
  NineSpheresRadius nine_spheres_radius =
      NineSpheresRadius::kWorld;      // nine_spheres_radius: world|equivalent
  ProbabilisticConfig probabilistic;  // confidence, probabilistic_budget, probabilistic_patience
};

// lod.select: which particles a brick keeps. uniform: the prefix of its z-order layout (a
// spatially uniform sample), grown to stand for the rest. nearest: in a brick whose kept spheres
// still cover its footprint several times over, the ones nearest the camera at their own radius
// (the dropped ones are behind them); sparse bricks keep the uniform prefix.
enum class LodSelect { kUniform, kNearest };

// lod: level of detail served from z-order brick prefixes.
struct LodConfig {
  int64_t budget = 0;       // budget: max particles drawn per frame (0 = unlimited)
  double fraction = 1.0;    // fraction: (0, 1] share of particles drawn
  double min_pixels = 0.0;  // min_pixels: screen-space rule; draw a brick prefix so that its
                            // particles' spacing is at least this many pixels (0 = off)
  bool point_path = false;  // point_path: sub-pixel spheres as CPU splats (approximate)
  LodSelect select = LodSelect::kUniform;  // select: uniform | nearest (style: spheres)
};

// A cutting plane (the cross-sections paper): particles with dot(n, x) > offset are dropped.
struct CutPlane {
  std::array<double, 3> normal{0, 0, 1};  // normal: [nx, ny, nz]
  double offset = 0.0;                    // offset: plane is dot(normal, x) = offset
  bool enabled = true;  // enabled: false keeps the plane in the list but cuts nothing (toggle)
};

// Depth cues, each off unless its section is present. The screen-space ones (screen
// ambient occlusion, outline, depth cue) run on the final-resolution composited frame, after
// any down-sampling and before the image is written (core/finish/screen_cues.h).
enum class AmbientOcclusionMethod { kScreen, kObject };
// Where screen ambient occlusion is estimated: on every other pixel of every other row, then
// blurred and brought back to every pixel by depth-aware upsampling (half), or at every pixel.
enum class AoResolution { kHalf, kFull };

// The default ambient_occlusion.radius, in sphere radii (the scene's largest): about the first
// neighbour shell of a dense packing.
inline constexpr double kDefaultAoRadiusInSphereRadii = 4.0;

// The most nodes of the object method's density volume, by default and at most (max_nodes): the
// default keeps its sums and smoothing at 2 MiB a rank; the largest at 64 MiB of deposits a
// thread (tests/bench/cues/results/object_ao_max_nodes.txt: time and error against the
// nominal spacing).
inline constexpr int64_t kDefaultAoMaxNodes = int64_t(1) << 18;
inline constexpr int64_t kLargestAoMaxNodes = int64_t(1) << 22;

// ambient_occlusion: {method, radius, samples, strength, resolution, max_nodes}
struct AmbientOcclusionConfig {
  bool enabled = false;                                             // the section is present
  AmbientOcclusionMethod method = AmbientOcclusionMethod::kScreen;  // method: screen | object
  std::optional<double> radius;  // radius: > 0, simulation units; absent = 4 x sphere radius
  int samples = 16;              // samples: 1..64 (screen: samples per estimate)
  double strength = 0.6;         // strength: [0, 1], 0 = no darkening
  AoResolution resolution = AoResolution::kHalf;  // resolution: half | full (method: screen)
  int64_t max_nodes = kDefaultAoMaxNodes;  // max_nodes: 64..kLargestAoMaxNodes (method: object)
};

// outline: {width, color, depth_threshold}
struct OutlineConfig {
  bool enabled = false;                  // the section is present
  int width = 1;                         // width: pixels, 1..16
  std::array<double, 3> color{0, 0, 0};  // color: [r, g, b]
  double depth_threshold = 1.0;          // depth_threshold: >= 0, in sphere radii
};

// depth_cue: {start, end, color}
struct DepthCueConfig {
  bool enabled = false;                        // the section is present
  std::optional<double> start;                 // start: view depth where fading begins; auto
  std::optional<double> end;                   // end: view depth of full fade; auto
  std::optional<std::array<double, 3>> color;  // color: [r, g, b]; absent = background
};

// style: what a particle is in the picture. spheres: opaque shaded spheres (depth-composited).
// density: a screen-aligned Gaussian footprint, summed over particles (Rizzi et al. 2015, §3.4;
// core/render/density_splat.h), then mapped to colors by `density:`.
enum class SceneStyle { kSpheres, kDensity };
enum class DensityTransfer { kLinear, kLog, kAsinh };

// density: how the summed footprints become an image (style: density only).
struct DensityConfig {
  DensityTransfer transfer = DensityTransfer::kLinear;  // transfer: linear | log | asinh
  std::optional<std::array<double, 2>> range;  // range: auto | [lo, hi] (summed particle weight)
  std::string colormap = "grayscale";          // colormap: of the intensity (color.by: solid)
};

// bonds: published bonds (lantern_publish_bonds) drawn as cylinders, each split at its midpoint
// into two half-bonds; off unless the section is present. color: by_atom gives each half its
// atom's sphere color (as LAMMPS's dump image and OVITO split a bond), by_type the color of the
// bond's type from `palette`, solid one `solid` color.
enum class BondColorBy { kAtom, kType, kSolid };

struct BondsConfig {
  bool enabled = false;                        // the section is present
  double radius = 0.15;                        // radius: > 0, the simulation's length unit
  BondColorBy color = BondColorBy::kAtom;      // color: by_atom | by_type | solid
  std::array<double, 3> solid{0.6, 0.6, 0.6};  // solid: [r, g, b] (color: solid)
  std::vector<std::array<double, 3>> palette;  // palette: per bond type; empty = built-in
};

// Overlays: drawn on rank 0 over the finished image (core/finish/overlays/), each off unless
// given. A place on the image: one of its corners (with a margin), or `at`, the overlay's
// top-left pixel counted from the image's top-left corner.
enum class OverlayCorner { kTopLeft, kTopRight, kBottomLeft, kBottomRight };
struct OverlayPlace {
  OverlayCorner corner = OverlayCorner::kTopLeft;
  std::optional<std::array<int, 2>> at;  // position: [x, y] pixels (instead of a corner)
  bool operator==(const OverlayPlace &o) const { return corner == o.corner && at == o.at; }
};

// labels: [{text, position, size, color}, ...]; text is a template with {step}, {step:06d},
// {time}, {time:.2f} and {scene} (core/config/label_template.h).
struct LabelConfig {
  std::string text;                      // text: the template (required)
  OverlayPlace position;                 // position: corner | [x, y]
  int size = 24;                         // size: font size, pixels 4..512
  std::array<double, 3> color{0, 0, 0};  // color: [r, g, b]
};

// legend: a colour bar (color.by: scalar) or a key of type names (color.by: type).
struct LegendConfig {
  bool enabled = false;                                              // the section is present
  OverlayPlace position{OverlayCorner::kBottomRight, std::nullopt};  // position: corner | [x, y]
  std::optional<int> length;             // length: the bar's length, pixels; absent = 40% of height
  int width = 16;                        // width: the bar's width (the key's swatches), pixels
  int font_size = 16;                    // font_size: pixels 4..512
  std::array<double, 3> color{0, 0, 0};  // color: text, ticks and frame [r, g, b]
  // title: above the bar; absent = the scalar's name (lammps.scalar, else "scalar"); none for
  // the type key unless given.
  std::optional<std::string> title;
  int ticks = 5;                        // ticks: about this many labelled values, 2..20
  std::vector<std::string> type_names;  // type_names: [Ni, flyer] - the key's entries, type 0..
};

// box: the simulation box's twelve edges, hidden where particles are in front of them.
struct BoxOverlayConfig {
  bool enabled = false;                  // the section is present
  std::array<double, 3> color{0, 0, 0};  // color: [r, g, b]
  double width = 1.5;                    // width: line width, pixels (0, 16]
};

// axes: a small x/y/z triad showing the camera's orientation.
struct AxesConfig {
  bool enabled = false;                                             // the section is present
  OverlayPlace position{OverlayCorner::kBottomLeft, std::nullopt};  // position: corner | [x, y]
  int size = 80;                                                    // size: pixels 16..1024
  int font_size = 14;                                               // font_size: pixels 4..512
};

struct SceneConfig {
  std::string name = "scene";  // name: used in stats and in {scene} of the pattern
  int width = 1024;            // width: pixels, 1..kMaxImageSize
  int height = 1024;           // height: pixels, 1..kMaxImageSize
  std::array<double, 3> background{1.0, 1.0, 1.0};  // background: [r, g, b] | transparent
  // background: transparent - pixels nothing covers get alpha 0 (PNG, TIFF, EXR keep it); then
  // `background` is unused and stays [1, 1, 1].
  bool transparent_background = false;
  double radius = 0.5;               // radius: a number, for every particle
  bool per_particle_radius = false;  // radius: per_particle  (uses the published radius array)
  CameraConfig camera;               // camera: {...}
  ColorConfig color;                 // color: {...}
  OutputConfig output;               // output: {...}
  CullingConfig culling;             // culling: {...}
  RendererChoice renderer = RendererChoice::kAuto;  // renderer: auto | opengl | cpu
  LodConfig lod;                                    // lod: {...}
  std::vector<CutPlane> cuts;  // cut_planes: [{normal: [...], offset: ...}, ...]
  // samples: super-sampled anti-aliasing, 1 | 4 | 16 | 64 rays per pixel on an s x s ordered
  // grid (s = sqrt(samples)); 1 (default) renders exactly as without the key.
  int samples = 1;
  int samples_per_axis() const {
    return samples >= 64 ? 8 : samples >= 16 ? 4 : samples >= 4 ? 2 : 1;
  }
  AmbientOcclusionConfig ambient_occlusion;  // ambient_occlusion: {...}
  // budget_ms: > 0, the milliseconds this scene may take per rendered step; Lantern lowers the
  // level of detail, samples and ambient occlusion as far as needed
  // (core/pipeline/render_budget.h). Absent: no budget, the scene renders exactly as configured.
  std::optional<double> budget_ms;
  OutlineConfig outline;                    // outline: {...}
  DepthCueConfig depth_cue;                 // depth_cue: {...}
  SceneStyle style = SceneStyle::kSpheres;  // style: spheres | density
  DensityConfig density;                    // density: {...}
  // opacity: [a0, a1, ...] per type, each in [0, 1] (screen-door transparency); types
  // beyond the list, and every type when it is empty (the default), are opaque.
  std::vector<double> opacity;
  Lighting lighting;  // lighting: {direction, ambient, diffuse, specular, shininess} (lighting.h)
  BondsConfig bonds;  // bonds: {radius, color, solid, palette}
  std::vector<LabelConfig> labels;  // labels: [{text, ...}, ...]
  LegendConfig legend;              // legend: {...}
  BoxOverlayConfig box;             // box: {...}
  AxesConfig axes;                  // axes: {...}
  // font: the overlays' font - a file (a path with '/') or a fontconfig family name; "" =
  // fontconfig's DejaVu Sans.
  std::string font;
  bool has_text() const { return !labels.empty() || legend.enabled || axes.enabled; }
  bool has_overlays() const { return has_text() || box.enabled; }
};

// dump.mode: what the first dump does with a file already at dump.file. create: refuse it (a
// message naming the key; nothing is touched); append: continue its time series (a restarted
// run), when it is one of Lantern's files with the same fields and precision; overwrite: replace
// it.
enum class DumpMode { kCreate, kAppend, kOverwrite };

// dump: (HDF5 / H5MD particle dumps)
struct DumpConfig {
  bool enabled = false;  // true when the `dump:` section is present (enabled: false turns it off)
  std::string file = "lantern_particles.h5";  // file:
  Schedule schedule;                          // schedule: {...}
  std::vector<std::string> fields;            // fields: [position, type, scalar, radius, id]
  bool single_precision = false;              // precision: float32 | float64
  DumpMode mode = DumpMode::kCreate;          // mode: create | append | overwrite
};

// gl: the OpenGL back end (core/render/gl/gl_context.h). auto: EGL, then OSMesa, then none; none:
// no OpenGL, every scene drawn by the CPU raster. The environment variable LANTERN_GL, when set,
// overrides the key (so a site can switch back ends without editing configurations).
enum class GlBackend { kAuto, kEgl, kOsmesa, kNone };

// lammps: read by the lantern-lammps program (adaptor/lammps), which drives LAMMPS; Lantern's
// pipeline ignores it.
struct LammpsConfig {
  std::string fix;  // fix: ID of the `fix ... external pf/callback` to attach to ("" = every one)
  // scalar: per-atom quantity published as the scalar, named as LAMMPS names it: c_ID or c_ID[N]
  // (a per-atom compute), v_name (an atom-style variable), or a per-atom property (vx, fz, q, ...)
  std::string scalar;
};

struct Config {
  Schedule schedule;                // schedule: {...}
  std::vector<SceneConfig> scenes;  // scenes: [...] (at least one, unless dump is set)
  std::string stats_file;           // stats: path of a JSON-lines file ("" = no stats)
  bool verbose = false;             // verbose: print a line per rendered step on rank 0
  DumpConfig dump;                  // dump: {...}
  GlBackend gl = GlBackend::kAuto;  // gl: auto | egl | osmesa | none  (env LANTERN_GL wins)
  // egl_device: auto (-1: hardware devices spread over the node's ranks, else the software
  // device) or an EGL device number. The environment variable LANTERN_EGL_DEVICE wins.
  int egl_device = -1;
  LammpsConfig lammps;  // lammps: {...}
  // watch: re-read the configuration file when it changes (checked on rank 0 at scheduled steps,
  // applied on every rank at the same step; needs the configuration to come from a file).
  bool watch = false;
  // threads: auto | N - the threads each rank may use for brick building and refitting, the
  // particle scan and the CPU raster (images are the same at any count). 0 (auto): what
  // OMP_NUM_THREADS or, without it, the process's CPU affinity gives (core/common/rank_threads.h).
  int threads = 0;
  // budget_percent: (0, 100], the share of the wall time between rendered steps (from the end of
  // one lantern_execute to the start of the next render) that all scenes together may take;
  // absent: none. Each scene gets a share in proportion to its full-quality cost.
  std::optional<double> budget_percent;
};

inline constexpr int kMaxImageSize = 16384;
// The largest super-sampled frame a scene may render (width * height * samples pixels, 8 bytes
// each: RGBA8 + float depth): 2^28 pixels, 2 GiB per rank. It is below compositing's INT_MAX / 4
// pixel limit, and fixed (not a share of this machine's memory) so every rank and every machine
// accepts the same configurations. samples: 1 keeps kMaxImageSize's limit.
inline constexpr int64_t kMaxSampleFramePixels = int64_t(1) << 28;

}  // namespace lantern
