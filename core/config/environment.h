// The environment variables that override a configuration: LANTERN_GL (the `gl` key: auto, egl,
// osmesa, none), LANTERN_EGL_DEVICE (the `egl_device` key: auto or a device number) and
// LANTERN_MOVIE_WHEN_BEHIND (every scene's output.movie.when_behind: drop or wait; lantern-render
// sets wait, since offline no simulation waits and every frame belongs in the movie). A site or a
// batch script can switch back ends without editing the configuration; an unset or empty
// variable changes nothing. Thread-safety: reads the process environment.
#pragma once

#include "core/common/status.h"
#include "core/config/config.h"

namespace lantern {

// Applies the variables to *config; a kConfig status naming the variable and its allowed values
// when one is set to something else.
Status apply_environment(Config *config);

}  // namespace lantern
