// Every configuration error names the key, its line (1-based) and path, and what is allowed.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/config/config_loader.h"
#include "tests/support/config_error_expect.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

using testing::expect_config_error;

TEST(ConfigErrors, UnknownKeyNamesKeyLinePathAndSuggestion) {
  expect_config_error(
      "scenes:\n"
      "  - name: front\n"
      "    camera:\n"
      "      azimth: 30\n",
      {"'azimth'", "line 4", "scenes[0].camera.azimth", "did you mean 'azimuth'?"});
}

TEST(ConfigErrors, KeyInTheWrongSectionSaysWhereItBelongs) {
  expect_config_error(
      "scenes:\n  - width: 10\n    azimuth: 30\n",
      {"scenes[0].azimuth", "line 3", "did you mean", "is a key of scenes[].camera"});
}

TEST(ConfigErrors, UnknownTopLevelKey) {
  expect_config_error("scene:\n  - {}\n", {"'scene'", "line 1", "did you mean 'scenes'?"});
  expect_config_error("scenes: [{}]\nverbos: true\n",
                      {"'verbos'", "line 2", "did you mean 'verbose'?"});
}

TEST(ConfigErrors, UnknownKeyInEverySection) {
  expect_config_error("schedule: {evry: 2}\nscenes: [{}]\n",
                      {"schedule.evry", "line 1", "did you mean 'every'?"});
  expect_config_error("scenes:\n  - {}\n  - widht: 3\n",
                      {"scenes[1].widht", "line 3", "did you mean 'width'?"});
  // British spelling: the keys are spelt "color"; a user typing "colour" gets a suggestion.
  expect_config_error("scenes:\n  - color: {colourmap: plasma}\n",
                      {"scenes[0].color.colourmap", "line 2", "did you mean 'colormap'?"});
  expect_config_error("scenes:\n  - output: {patern: x.png}\n",
                      {"scenes[0].output.patern", "line 2", "did you mean 'pattern'?"});
  expect_config_error("scenes:\n  - culling: {frustrum: true}\n",
                      {"scenes[0].culling.frustrum", "line 2", "did you mean 'frustum'?"});
  expect_config_error("scenes:\n  - lod: {fractoin: 0.5}\n",
                      {"scenes[0].lod.fractoin", "line 2", "did you mean 'fraction'?"});
  expect_config_error("scenes:\n  - cut_planes:\n      - {normal: [1, 0, 0], ofset: 1}\n",
                      {"scenes[0].cut_planes[0].ofset", "line 3", "did you mean 'offset'?"});
  expect_config_error("dump: {fiel: a.h5}\n", {"dump.fiel", "line 1", "did you mean 'file'?"});
}

TEST(ConfigErrors, DuplicateKey) {
  expect_config_error("scenes:\n  - width: 3\n    width: 4\n",
                      {"duplicate key 'width'", "line 3", "line 2"});
}

TEST(ConfigErrors, MalformedYamlGivesLineAndColumn) {
  expect_config_error("scenes:\n  - width: [1, 2\n  - height: 3\n",
                      {"malformed YAML", "line", "column"});
  expect_config_error("scenes: [{}]\n  bad: indentation: here\n", {"malformed YAML", "line 2"});
}

TEST(ConfigErrors, UnreadableFileIsNamed) {
  expect_config_error("/nonexistent/lantern.yaml", {"/nonexistent/lantern.yaml", "No such file"});
  expect_config_error("/tmp", {"'/tmp'", "is a directory, not a regular file"});
}

TEST(ConfigErrors, NothingToDo) {
  expect_config_error("verbose: true\n", {"scenes"});
  expect_config_error("scenes: []\n", {"scenes"});
  expect_config_error("\n", {"scenes"});
}

TEST(ConfigErrors, WrongShape) {
  expect_config_error("- a\n- b\n", {"mapping"});
  expect_config_error("scenes: {width: 3}\n", {"scenes", "list"});
  expect_config_error("scenes:\n  - 42\n", {"scenes[0]", "line 2", "mapping"});
  expect_config_error("scenes:\n  - camera: 3\n", {"scenes[0].camera", "line 2", "mapping"});
}

TEST(ConfigErrors, ImageSize) {
  expect_config_error("scenes:\n  - width: 0\n",
                      {"scenes[0].width", "line 2", "1..16384", "got 0"});
  expect_config_error("scenes:\n  - height: 16385\n", {"scenes[0].height", "line 2", "1..16384"});
  expect_config_error("scenes:\n  - width: 12.5\n", {"scenes[0].width", "integer", "'12.5'"});
  expect_config_error("scenes:\n  - width: big\n", {"scenes[0].width", "integer", "'big'"});
}

TEST(ConfigErrors, Radius) {
  expect_config_error("scenes:\n  - radius: 0\n",
                      {"scenes[0].radius", "line 2", "> 0", "per_particle"});
  expect_config_error("scenes:\n  - radius: -1\n", {"scenes[0].radius", "> 0"});
  expect_config_error("scenes:\n  - radius: .nan\n", {"scenes[0].radius", "finite"});
  expect_config_error("scenes:\n  - radius: .inf\n", {"scenes[0].radius", "finite"});
  expect_config_error("scenes:\n  - radius: per-particle\n", {"scenes[0].radius", "per_particle"});
}

TEST(ConfigErrors, Camera) {
  expect_config_error("scenes:\n  - camera: {fov: 180}\n",
                      {"scenes[0].camera.fov", "line 2", "(0, 180)"});
  expect_config_error("scenes:\n  - camera: {fov: 0}\n", {"scenes[0].camera.fov", "(0, 180)"});
  expect_config_error("scenes:\n  - camera: {zoom: 0}\n", {"scenes[0].camera.zoom", "> 0"});
  expect_config_error("scenes:\n  - camera: {elevation: 91}\n",
                      {"scenes[0].camera.elevation", "[-90, 90]"});
  expect_config_error("scenes:\n  - camera: {projection: fisheye}\n",
                      {"scenes[0].camera.projection", "perspective, orthographic", "'fisheye'"});
  expect_config_error("scenes:\n  - camera: {position: [1, 2]}\n",
                      {"scenes[0].camera.position", "3 finite numbers"});
  expect_config_error("scenes:\n  - camera: {look_at: [1, 2, 3]}\n",
                      {"scenes[0].camera.look_at", "position"});
  expect_config_error("scenes:\n  - camera: {position: [1, 2, 3], look_at: [1, 2, 3]}\n",
                      {"scenes[0].camera.look_at", "differ"});
  expect_config_error("scenes:\n  - camera: {up: [0, 0, 0]}\n", {"scenes[0].camera.up", "zero"});
  expect_config_error("scenes:\n  - camera: {near: 10, far: 5}\n",
                      {"scenes[0].camera.far", "> 10"});
}

TEST(ConfigErrors, CameraPath) {
  const std::string scene = "scenes:\n  - camera:\n      path:\n";
  expect_config_error(scene + "        - {step: 0}\n        - {step: 500, azimuth: 90}\n" +
                          "        - {step: 200, azimuth: 180}\n",
                      {"scenes[0].camera.path[2]", "line 6", "step 200",
                       "previous keyframe's step 500", "increasing step order"});
  expect_config_error(scene + "        - {step: 10}\n        - {step: 10, zoom: 2}\n",
                      {"scenes[0].camera.path[1]", "step 10 is not after"});
  expect_config_error(scene + "        - {step: 0, azimth: 10}\n",
                      {"scenes[0].camera.path[0].azimth", "line 4", "did you mean 'azimuth'?",
                       "step, azimuth, elevation, zoom"});
  expect_config_error(scene + "        - {step: 0, azimuth: .nan}\n",
                      {"scenes[0].camera.path[0].azimuth", "finite"});
  expect_config_error(scene + "        - {step: 0, zoom: .inf}\n",
                      {"scenes[0].camera.path[0].zoom", "> 0"});
  expect_config_error(scene + "        - {step: 0, elevation: 95}\n",
                      {"scenes[0].camera.path[0].elevation", "[-90, 90]"});
  expect_config_error(scene + "        - {step: -1}\n", {"scenes[0].camera.path[0].step"});
  expect_config_error(scene + "        - {step: 9007199254740993}\n",
                      {"scenes[0].camera.path[0].step", "9007199254740992"});
  expect_config_error(scene + "        - {azimuth: 10}\n",
                      {"scenes[0].camera.path[0]", "needs 'step'"});
  expect_config_error(scene + "        - 5\n", {"scenes[0].camera.path[0]", "mapping"});
  expect_config_error("scenes:\n  - camera: {path: []}\n",
                      {"scenes[0].camera.path", "at least one keyframe"});
  expect_config_error(
      scene + "        - {step: 0, azimuth: 0}\n        - {step: 9, azimuth: 360}\n",
      {"scenes[0].camera.path[1].azimuth", "line 5", "turns 360 degrees",
       "add a keyframe in between"});
  expect_config_error("scenes:\n  - camera:\n      position: [0, 0, 9]\n      path: [{step: 0}]\n",
                      {"scenes[0].camera.path", "line 4", "explicit camera"});
  expect_config_error(
      "scenes:\n  - camera:\n      path: [{step: 0}]\n      orbit: {degrees_per_step: 1}\n",
      {"scenes[0].camera.orbit", "line 4", "not both"});
}

TEST(ConfigErrors, CameraOrbit) {
  expect_config_error("scenes:\n  - camera: {orbit: {}}\n",
                      {"scenes[0].camera.orbit", "needs 'degrees_per_step'"});
  expect_config_error("scenes:\n  - camera: {orbit: {degrees_per_step: 400}}\n",
                      {"scenes[0].camera.orbit.degrees_per_step", "[-360, 360]"});
  expect_config_error("scenes:\n  - camera: {orbit: {degrees_per_step: .nan}}\n",
                      {"scenes[0].camera.orbit.degrees_per_step", "finite"});
  expect_config_error(
      "scenes:\n  - camera: {orbit: {degrees_per_stp: 1}}\n",
      {"scenes[0].camera.orbit.degrees_per_stp", "did you mean 'degrees_per_step'?"});
  expect_config_error("scenes:\n  - camera: {orbit: 2}\n",
                      {"scenes[0].camera.orbit", "{degrees_per_step: d}"});
  expect_config_error("scenes:\n  - camera: {position: [1, 1, 1], orbit: {degrees_per_step: 1}}\n",
                      {"scenes[0].camera.orbit", "explicit camera"});
}

TEST(ConfigErrors, Color) {
  expect_config_error(
      "scenes:\n  - color: {colormap: jet}\n",
      {"scenes[0].color.colormap", "line 2",
       "viridis, plasma, inferno, magma, cividis, turbo, coolwarm, RdBu, seismic, grayscale",
       "'jet'"});
  expect_config_error("scenes:\n  - color: {by: velocity}\n",
                      {"scenes[0].color.by", "solid, type, scalar"});
  expect_config_error("scenes:\n  - color: {range: [2, 1]}\n",
                      {"scenes[0].color.range", "auto", "min < max"});
  expect_config_error("scenes:\n  - color: {range: automatic}\n",
                      {"scenes[0].color.range", "auto"});
  expect_config_error("scenes:\n  - color: {solid: [1, 2, 0]}\n",
                      {"scenes[0].color.solid[1]", "[0, 1]"});
  expect_config_error("scenes:\n  - background: [0, 0]\n", {"scenes[0].background", "[r, g, b]"});
  expect_config_error("scenes:\n  - color: {palette: []}\n", {"scenes[0].color.palette"});
}

TEST(ConfigErrors, Output) {
  expect_config_error("scenes:\n  - output: {jpeg_quality: 101}\n",
                      {"scenes[0].output.jpeg_quality", "line 2", "1..100"});
  expect_config_error("scenes:\n  - output: {compression_level: 10}\n",
                      {"scenes[0].output.compression_level", "line 2", "0..9"});
  expect_config_error("scenes:\n  - output: {pattern: 'f_{stp}.png'}\n",
                      {"scenes[0].output.pattern", "line 2", "{stp}", "{step:0Nd}"});
  expect_config_error("scenes:\n  - output: {pattern: 'frame_{step}'}\n",
                      {"scenes[0].output.pattern", "extension", "format"});
  expect_config_error("scenes:\n  - output: {pattern: 'a.png', format: exr}\n",
                      {"scenes[0].output.format", "contradicts"});
  expect_config_error("scenes:\n  - output: {pattern: 'a', format: bmp}\n",
                      {"scenes[0].output.format", "png, jpeg", "exr"});
  expect_config_error("scenes:\n  - output: {pattern: 'a.exr', exr_color: double}\n",
                      {"scenes[0].output.exr_color", "half, float"});
}

TEST(ConfigErrors, ScenesMustNotOverwriteEachOther) {
  expect_config_error("scenes:\n  - {name: a}\n  - {name: b}\n",
                      {"scenes[1].output.pattern", "scenes[0]", "{scene}"});
  expect_config_error(
      "scenes:\n  - {name: a, output: {pattern: '{scene}.png'}}\n"
      "  - {name: a, output: {pattern: '{scene}.png'}}\n",
      {"scenes[1].name", "'a'", "scenes[0]"});
  expect_config_error("scenes:\n  - {name: 'a/b'}\n", {"scenes[0].name", "letters"});
}

TEST(ConfigErrors, CullingAndLod) {
  expect_config_error("scenes:\n  - culling: {occlusion: nine_sphere}\n",
                      {"scenes[0].culling.occlusion",
                       "auto, none, nine_spheres, nine_spheres_sorted, hzb, probabilistic",
                       "did you mean 'nine_spheres'?"});
  expect_config_error(
      "scenes:\n  - culling: {nine_spheres_radius: equivalnt}\n",
      {"scenes[0].culling.nine_spheres_radius", "world, equivalent", "did you mean 'equivalent'?"});
  expect_config_error("scenes:\n  - culling: {frustum: maybe}\n",
                      {"scenes[0].culling.frustum", "true or false"});
  expect_config_error("scenes:\n  - lod: {fraction: 0}\n", {"scenes[0].lod.fraction", "(0, 1]"});
  expect_config_error("scenes:\n  - lod: {fraction: 1.5}\n", {"scenes[0].lod.fraction", "(0, 1]"});
  expect_config_error("scenes:\n  - lod: {budget: -1}\n", {"scenes[0].lod.budget", "integer"});
  expect_config_error("scenes:\n  - lod: {min_pixels: -1}\n", {"scenes[0].lod.min_pixels", ">= 0"});
  expect_config_error("scenes:\n  - cut_planes: [{normal: [0, 0, 0]}]\n",
                      {"scenes[0].cut_planes[0].normal", "zero"});
}

TEST(ConfigErrors, Schedule) {
  expect_config_error("schedule: {every: -1}\nscenes: [{}]\n",
                      {"schedule.every", "line 1", "integer"});
  expect_config_error("schedule:\n  steps: [0, -5]\nscenes: [{}]\n",
                      {"schedule.steps[1]", "line 2", "integer"});
  expect_config_error("schedule: {steps: []}\nscenes: [{}]\n", {"schedule.steps", "at least one"});
  expect_config_error("schedule: {steps: 5}\nscenes: [{}]\n", {"schedule.steps", "list"});
}

TEST(ConfigErrors, TopLevelTypes) {
  expect_config_error("verbose: loud\nscenes: [{}]\n", {"verbose", "line 1", "true or false"});
  expect_config_error("stats: [a]\nscenes: [{}]\n", {"stats", "string"});
  expect_config_error("dump: {precision: float16}\n", {"dump.precision", "float32, float64"});
  expect_config_error("dump: {mode: truncate}\n", {"dump.mode", "create, append, overwrite"});
  expect_config_error("dump: {fields: [position, velocity]}\n",
                      {"dump.fields[1]", "position, type, scalar, radius, id"});
}

// A NUL inside a string ("\0" in a double-quoted YAML string) used to be
// accepted, and the operating system cut the file name there (every step wrote "o/a").
TEST(ConfigErrors, NulCharacterInAStringIsRejectedNamingTheKey) {
  expect_config_error(
      "scenes:\n  - output: {pattern: \"o/a\\0b{step}.png\"}\n",
      {"scenes[0].output.pattern", "line 2", "NUL", "byte 3", "'o/a\\0b{step}.png'"});
  expect_config_error("stats: \"s\\0.jsonl\"\nscenes: [{}]\n", {"stats", "line 1", "NUL"});
  expect_config_error("dump: {file: \"d\\0.h5\"}\n", {"dump.file", "NUL"});
  expect_config_error("scenes:\n  - name: \"a\\0b\"\n", {"scenes[0].name", "line 2"});
}

// A second document used to be ignored without a word.
TEST(ConfigErrors, SecondYamlDocumentIsAnError) {
  expect_config_error("scenes: [{}]\n---\nscenes: [{width: 8}]\n",
                      {"second YAML document", "line 3", "one document"});
  expect_config_error("scenes: [{}]\n---\n", {"second YAML document"});
  // One document, with the optional start and end markers, stays valid.
  Config c;
  EXPECT_TRUE(load_config("---\nscenes: [{}]\n...\n", &c).ok());
}

// A binary file read as configuration gave a message carrying its raw bytes.
TEST(ConfigErrors, BinaryContentIsEscapedAndCutShort) {
  std::string bytes;
  uint32_t x = 12345;
  for (int i = 0; i < 4096; ++i) {
    x = x * 1664525u + 1013904223u;  // deterministic "random" bytes
    bytes += static_cast<char>(x >> 24);
  }
  const std::string path =
      (std::filesystem::temp_directory_path() / "lantern_config_binary.yaml").string();
  std::ofstream(path, std::ios::binary) << bytes;
  // The same bytes inline (a newline makes it a document) and as a file.
  for (const std::string &source : {"\n" + bytes, path}) {
    Config c;
    const Status status = load_config(source, &c);
    EXPECT_EQ(status.code, StatusCode::kConfig);
    for (const char ch : status.message)
      ASSERT_TRUE(ch >= 0x20 && ch <= 0x7e) << "unprintable byte in: " << status.message;
    EXPECT_LT(status.message.size(), 400u) << status.message;
  }
  std::filesystem::remove(path);
  // A long value is cut short with an ellipsis, an unprintable byte escaped (YAML's "\x8f" is
  // U+008F, the UTF-8 bytes c2 8f).
  const std::string long_value(500, 'q');
  const std::string error =
      expect_config_error("scenes:\n  - color: {colormap: \"\\x8f" + long_value + "\"}\n",
                          {"scenes[0].color.colormap", "'\\xc2\\x8fqqq", "qqq'..."});
  EXPECT_LT(error.size(), 300u) << error;
  expect_config_error("\"\\x01\": 1\n", {"unknown key '\\x01'"});
}

// The probabilistic culling keys (Ibrahim et al. 2022): C_occ strictly inside (0, 1), the budget
// and patience whole numbers in range, and a renderer that can serve probabilistic culling (only
// the CPU raster can).
TEST(ConfigErrors, ProbabilisticCulling) {
  for (const char *bad : {"0", "1", "1.5", "x"})
    expect_config_error(
        std::string("scenes:\n  - culling: {occlusion: probabilistic, confidence: ") + bad + "}\n",
        {"line 2", "scenes[0].culling.confidence", "(0, 1)"});
  expect_config_error("scenes:\n  - culling: {occlusion: probabilistic, probabilistic_budget: 0}\n",
                      {"line 2", "scenes[0].culling.probabilistic_budget", "1", "64"});
  expect_config_error("scenes:\n  - culling: {probabilistic_budget: two}\n",
                      {"scenes[0].culling.probabilistic_budget"});
  expect_config_error("scenes:\n  - culling: {probabilistic_patience: 100}\n",
                      {"scenes[0].culling.probabilistic_patience", "64"});
  expect_config_error(
      "scenes:\n  - width: 8\n    culling: {occlusion: probabilistic}\n    renderer: opengl\n",
      {"line 4", "scenes[0].renderer", "'opengl'", "probabilistic",
       "a renderer that cannot serve it", "auto, cpu"});
  // Accepted: the CPU raster, or auto (which picks it).
  for (const char *renderer : {"cpu", "auto"}) {
    Config c;
    EXPECT_OK(
        load_config(std::string("scenes:\n  - culling: {occlusion: probabilistic, "
                                "confidence: 0.99, probabilistic_budget: 4}\n    renderer: ") +
                        renderer + "\n",
                    &c));
    ASSERT_EQ(c.scenes.size(), 1u);
    EXPECT_EQ(c.scenes[0].culling.occlusion, OcclusionMode::kProbabilistic);
    EXPECT_EQ(c.scenes[0].culling.probabilistic.confidence, 0.99);
    EXPECT_EQ(c.scenes[0].culling.probabilistic.budget, 4);
  }
}

}  // namespace
}  // namespace lantern
