#include "core/config/live_change.h"

#include <string>

#include "core/config/enum_names.h"
#include "core/config/file_pattern.h"

namespace lantern {
namespace {

Status fixed(const std::string &key, const std::string &running, const std::string &next,
             const std::string &why) {
  return {StatusCode::kConfig, key + ": cannot change while running (" + why + "; running '" +
                                   running + "', new '" + next +
                                   "'): close the context and open a new one to change it"};
}

std::string joined(const std::vector<std::string> &words) {
  std::string out;
  for (const std::string &w : words) out += (out.empty() ? "" : ", ") + w;
  return "[" + out + "]";
}

// A movie file being written keeps its codec and frame size: a scene may start a new file, not
// change the one it writes.
Status check_movie_change(const SceneConfig &a, const SceneConfig &b) {
  const MovieConfig &m = a.output.movie, &n = b.output.movie;
  if (!m.enabled || !n.enabled) return {};
  const std::string file = expand_pattern(m.file, 0, a.name);
  if (file != expand_pattern(n.file, 0, b.name)) return {};
  const auto size = [](const SceneConfig &s) {
    return std::to_string(s.width) + " x " + std::to_string(s.height);
  };
  if (m != n || size(a) != size(b))
    return {StatusCode::kConfig,
            "scenes '" + b.name + "': output.movie: '" + file +
                "' cannot change its settings or frame size while it is written (running " +
                m.codec + " " + size(a) + ", new " + n.codec + " " + size(b) +
                "): give output.movie.file a new name to start another movie"};
  return {};
}

}  // namespace

Status check_live_change(const Config &running, const Config &next) {
  for (const SceneConfig &b : next.scenes)
    for (const SceneConfig &a : running.scenes)
      if (a.name == b.name)
        if (Status s = check_movie_change(a, b); !s.ok()) return s;
  if (running.gl != next.gl)
    return fixed("gl", name_of(running.gl), name_of(next.gl),
                 "the OpenGL back end is chosen at lantern_open");
  if (running.egl_device != next.egl_device)
    return fixed("egl_device", std::to_string(running.egl_device), std::to_string(next.egl_device),
                 "the EGL device is chosen at lantern_open");
  const DumpConfig &a = running.dump, &b = next.dump;
  const char *open_file = "the H5MD file stays open until lantern_close";
  if (a.enabled != b.enabled)
    return fixed("dump", a.enabled ? "on" : "off", b.enabled ? "on" : "off", open_file);
  if (!a.enabled) return {};
  if (a.file != b.file) return fixed("dump.file", a.file, b.file, open_file);
  if (a.fields != b.fields)
    return fixed("dump.fields", joined(a.fields), joined(b.fields),
                 "the file's datasets are made at the first dump");
  if (a.mode != b.mode)
    return fixed("dump.mode", name_of(a.mode), name_of(b.mode),
                 "it applies when the file is opened");
  if (a.single_precision != b.single_precision)
    return fixed("dump.precision", a.single_precision ? "float32" : "float64",
                 b.single_precision ? "float32" : "float64",
                 "the file's datasets are made at the first dump");
  return {};
}

}  // namespace lantern
