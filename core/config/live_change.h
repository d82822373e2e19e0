// What a running configuration may not change (lantern_reconfigure, watch: true): the parts
// that stand for resources opened once at lantern_open and held until lantern_close.
//
//  - gl, egl_device: the OpenGL back end and device (one GL session per context).
//  - dump.enabled, dump.file, dump.fields, dump.precision, dump.mode: the H5MD file stays open and
//  its
//    datasets have the fields and precision of the first frame. dump.schedule may change.
//
// Everything else - scenes (added, removed, edited), schedule, stats, verbose, watch - may change.
// Thread-safety: pure function.
#pragma once

#include "core/common/status.h"
#include "core/config/config.h"

namespace lantern {

// OK when `next` may replace `running`; otherwise kConfig naming the first key that would
// change and why it may not.
Status check_live_change(const Config &running, const Config &next);

}  // namespace lantern
