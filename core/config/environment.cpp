#include "core/config/environment.h"

#include <cstdlib>
#include <string>

#include "core/config/enum_names.h"

namespace lantern {
namespace {

std::string joined(const std::vector<std::string> &names) {
  std::string s;
  for (const std::string &n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

}  // namespace

Status apply_environment(Config *config) {
  if (const char *v = std::getenv("LANTERN_GL"); v && *v) {
    const std::optional<GlBackend> backend = value_of<GlBackend>(v);
    if (!backend)
      return {StatusCode::kConfig, std::string("LANTERN_GL: '") + v + "' is not one of " +
                                       joined(names_of<GlBackend>())};
    config->gl = *backend;
  }
  if (const char *v = std::getenv("LANTERN_EGL_DEVICE"); v && *v) {
    const std::string s(v);
    if (s == "auto") {
      config->egl_device = -1;
    } else {
      char *end = nullptr;
      const long n = std::strtol(v, &end, 10);
      if (*end != '\0' || n < 0 || n > 1023)
        return {StatusCode::kConfig,
                "LANTERN_EGL_DEVICE: '" + s + "' is not 'auto' or a device number 0..1023"};
      config->egl_device = int(n);
    }
  }
  if (const char *v = std::getenv("LANTERN_MOVIE_WHEN_BEHIND"); v && *v) {
    const std::optional<MovieWhenBehind> when = value_of<MovieWhenBehind>(v);
    if (!when)
      return {StatusCode::kConfig, std::string("LANTERN_MOVIE_WHEN_BEHIND: '") + v +
                                       "' is not one of " + joined(names_of<MovieWhenBehind>())};
    for (SceneConfig &scene : config->scenes) scene.output.movie.when_behind = *when;
  }
  return {};
}

}  // namespace lantern
