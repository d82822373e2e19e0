// Row bands of a composited image: the stages after compositing (down-sampling super-sampled
// frames, screen-space cues) run on every rank at once, each on its own band of rows, instead of
// serially on the root.
//
// The bands are a function of (height, ranks, multiple) only, so every stage that works band by
// band gives the same bytes at any rank count: the work is cut differently, never the result.
// A stage that reads neighbouring rows (a filter, ambient occlusion) asks for a halo: the band is
// handed out with up to `halo` extra rows above and below, clamped to the image.
//
// Collective: every rank calls with the same width, height, multiple, halo and root. Ownership:
// the functions read `full` (root only) and fill the caller's frames. Never throw.
// Limit: a band (with its halo) moves as at most INT_MAX pixels in one MPI call.
#pragma once

#include <mpi.h>

#include <optional>

#include "core/common/status.h"
#include "core/view/frame.h"

namespace lantern {

// Rows [y0, y1) of an image, y0 counted from the top.
struct RowBand {
  int y0 = 0;
  int y1 = 0;
  int rows() const { return y1 - y0; }
};

// The rows rank `rank` of `ranks` owns: contiguous, in rank order, covering [0, height), every
// boundary a multiple of `multiple` (which must divide height), sizes differing by at most
// `multiple` rows. So band(H * s, r, k, s) is band(H, r, k, 1) scaled by s: a super-sampled
// frame's bands down-sample into the final image's bands. A rank may own no rows.
RowBand row_band(int height, int ranks, int rank, int multiple = 1);

// A band of rows with its halo, as one rank holds it: `frame` is width x (last - first) pixels,
// holding image rows [first, last); the rank owns `owned` (inside [first, last)). Where `held` is
// set, only its rows (inside [first, last)) hold pixels of the image, the owned rows and their
// halo, and the frame's other rows are spare: a rank's whole merged frame, whose owned rows stay
// where compositing merged them.
struct BandFrame {
  Frame frame;
  int first = 0;  // image row of frame row 0
  RowBand owned;
  std::optional<RowBand> held;
  // The image rows that hold pixels: `held`, else every row of the frame.
  RowBand held_rows() const { return held ? *held : RowBand{first, first + frame.height}; }
};

// `owned` with up to `halo` rows above and below, clamped to [0, height) (empty if owned is).
RowBand with_halo(const RowBand &owned, int height, int halo);

// Hands root's `full` (width x height) out in bands: every rank gets its row_band(height, ranks,
// rank, multiple) plus up to `halo` rows on each side in *band. `full` matters on root only.
// OK or kMpi (the same on every rank).
Status scatter_row_bands(MPI_Comm comm, int root, const Frame &full, int width, int height,
                         int multiple, int halo, BandFrame *band);

// The inverse without halos: every rank's owned rows of band->frame (width x height image,
// bands of row_band(height, ranks, rank, 1)) are assembled into *full on root, which is resized
// to width x height there. OK or kMpi (the same on every rank).
Status gather_row_bands(MPI_Comm comm, int root, const BandFrame &band, int width, int height,
                        Frame *full);

// Widens every rank's band by its halo without a root: on entry band->frame holds the rank's
// owned = row_band(height, ranks, rank, multiple), width pixels a row, either exactly
// (band->first == owned.y0), or already in place among the rows with_halo(owned, height, halo)
// (band->first == their y0), or among the rows of the whole image (band->first == 0, height
// rows); the other rows' contents do not matter. On return the halo rows hold what the ranks that
// own them received (any number of ranks away, point to point: only ranks whose rows meet
// exchange any), and band->held is with_halo(owned, height, halo): in a band of exactly its
// rows, widened to those rows in its own buffers (no allocation once they are large enough), in
// the others in place. A rank that owns no rows gets none. OK or kMpi (the same on every rank).
Status exchange_halo_rows(MPI_Comm comm, int width, int height, int halo, BandFrame *band,
                          int multiple = 1);

}  // namespace lantern
