// Which pixels of a rank's frame compositing has to move: the "active" ones, as IceT calls them
// (Moreland, Kendall, Peterka and Huang, "An Image Compositing Solution at Scale", SC 2011).
//
// Exactness: compositing keeps, per pixel, the smallest packed key (packed_pixel.h) over the
// ranks. Let E be the largest key any rank holds anywhere (agreed in one reduction). Every key is
// <= E, so min(x, E) = x: a pixel whose key is E changes nothing where it is merged and need not
// be sent, and a pixel nobody sends is E. Skipping exactly the pixels equal to E is therefore
// bit-identical to merging every pixel, whatever the frames hold - no assumption about the
// background, the clear colour or the renderer. In a rendered frame E is the background (window
// depth 1, the background colour), so a rank sends what it drew.
//
// The scan also writes every depth back in its canonical form (canonical_depth: -0 and negative
// depths as +0, NaN as background), which is what a merged pixel holds, so that a pixel that no
// message touches ends up with the same bits as one that went through the merge.
//
// Plain functions over one frame; no MPI calls (ScanAgreement only adds to a RankAgreement).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "core/composite/rank_agreement.h"
#include "core/view/frame.h"

namespace lantern {

// A rectangle of pixels [x0, x1) x [y0, y1), y counted from the top row; empty when x0 >= x1 or
// y0 >= y1. (Half-open, unlike the view's inclusive PixelRect, core/view/view_geometry.h: a name
// of its own, so that the two never meet as one class with two definitions.)
struct ActiveRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;

  bool empty() const { return x0 >= x1 || y0 >= y1; }
  int64_t area() const { return empty() ? 0 : int64_t(x1 - x0) * (y1 - y0); }
  // The smallest rectangle holding this one and [x0, x1) x [y0, y1).
  void add(int ax0, int ay0, int ax1, int ay1) {
    if (ax0 >= ax1 || ay0 >= ay1) return;
    if (empty()) {
      *this = {ax0, ay0, ax1, ay1};
      return;
    }
    x0 = std::min(x0, ax0), y0 = std::min(y0, ay0);
    x1 = std::max(x1, ax1), y1 = std::max(y1, ay1);
  }
  void add(const ActiveRect &r) { add(r.x0, r.y0, r.x1, r.y1); }
};

// What one pass over a frame finds.
struct ActiveScan {
  uint64_t max_key = 0;  // the largest packed key in the frame (0 for an empty frame)
  ActiveRect rect;       // bounding rectangle of the pixels whose key is not max_key
  size_t active = 0;     // how many pixels' keys are not max_key
};

// Canonicalises frame's depths in place and returns its largest key, the bounding rectangle of
// the other pixels and their count. One pass; each row is first tallied against the running
// maximum in one vectorised sweep, and only rows that may hold a new maximum or a depth to
// rewrite are walked pixel by pixel. Where the renderer said where it drew
// (frame.drawn_within), only that rectangle is read (the same result: the pixels outside hold
// the background), and frame.drawn_within is dropped.
ActiveScan scan_active_pixels(Frame &frame);

// An estimate from every row_step-th row (starting at row_step / 2), for deciding whether a full
// scan pays: max_key and rect as scan_active_pixels finds them on those rows, active their count
// scaled to the whole frame. Canonicalises the depths of the rows it reads (as the full scan
// does), nothing else.
ActiveScan sample_active_pixels(Frame &frame, int row_step);

// What compositing must agree on about the ranks' scans, in the one RankAgreement it reduces
// (rank_agreement.h): the largest scan.max_key (the empty pixel E), the smallest, and the largest
// scan.active.
struct ScanAgreement {
  size_t max_key, min_key, most_active;
  ScanAgreement(RankAgreement &agree, const ActiveScan &scan)
      : max_key(agree.maximum(static_cast<long long>(scan.max_key))),
        min_key(agree.minimum(static_cast<long long>(scan.max_key))),
        most_active(agree.maximum(static_cast<long long>(scan.active))) {}

  // After agree.reduce().
  uint64_t empty_key(const RankAgreement &agree) const { return uint64_t(agree.max(max_key)); }
  // The busiest rank's active pixels, for the cost model. A rank whose own maximum is below E has
  // no empty pixel: all `pixels` of its frame are active.
  size_t busiest(const RankAgreement &agree, size_t pixels) const {
    return uint64_t(agree.min(min_key)) < empty_key(agree) ? pixels
                                                           : size_t(agree.max(most_active));
  }
};

// The agreed empty pixel E (the largest key over every rank) as the frame stores it, for
// comparisons without unpacking: depth bits and the 4 colour bytes as one word in memory order.
struct EmptyPixel {
  uint64_t key = 0;
  uint32_t depth_bits = 0;
  uint32_t rgba_word = 0;
};
EmptyPixel empty_pixel(uint64_t key);

// A frame as compositing sees it once scanned: every depth canonical, and every pixel outside
// `rect` equal to `empty`. Merges keep both true (a merged pixel is canonical, and rect grows to
// hold every pixel merged in).
struct ActiveFrame {
  Frame *frame = nullptr;
  EmptyPixel empty;
  ActiveRect rect;
};

}  // namespace lantern
