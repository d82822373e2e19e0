// Handing the memory a rendered step freed back to the operating system.
//
// Why: a step allocates and frees tens of bytes per particle of temporaries (the brick build's
// keys, the scan's and culling's buffers). glibc's malloc raises its mmap threshold to the size
// of the largest block freed (up to 32 MiB), so after the first step those temporaries come from
// the heap, and freed heap memory stays resident: 2-4 bytes per particle more between frames at
// 10 M particles per rank (lantern-bench --scale, retained B/p), memory the simulation cannot use.
// malloc_trim(0) returns the free pages of every arena (about 0.5 ms per step measured there).
// It only releases memory nobody holds, so it changes nothing the host sees but its resident
// size; a later allocation pays a page fault per page it touches again.
//
// Thread-safety: as malloc's. Elsewhere than glibc: nothing to do (returns false).
#pragma once

namespace lantern {

// Returns the process's free heap memory to the system; true where the C library can.
bool release_freed_memory();

}  // namespace lantern
