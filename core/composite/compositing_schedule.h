// Who sends which pixels to whom when p ranks merge their frames: the radix-k family of schedules
// (Peterka, Goodell, Ross, Shen and Thakur, "A Configurable Algorithm for Parallel
// Image-Compositing Applications", SC 2009), of which binary swap (every round of radix 2) and
// direct send (one round of radix p) are two configurations, plus folding for rank counts whose
// factorisation is poor (a prime p, say).
//
// The base: q = k_1 * ... * k_m "groups" of ranks run the rounds. With folding (q < p) the first
// p - q groups hold two consecutive ranks (2g, 2g + 1): the second, the "extra" rank, first hands
// its whole frame to the first, the group's "base" rank, and takes no further part in the rounds;
// the other groups are one rank each. q >= p / 2, so a base rank takes at most one extra.
//
// The rounds: group g has the mixed-radix digits (d_1, ..., d_m) of g, d_1 the most significant.
// The frame is cut into q contiguous "blocks" (block g is what group g ends up owning, merged over
// every rank). Before round j, group g holds the blocks whose first j - 1 digits are its own - a
// contiguous run of blocks; in round j it keeps the k_j-th part with its own digit d_j and
// exchanges every other part with the k_j - 1 groups that differ from it in digit j only. After
// the last round, group g's base rank holds block g merged over every rank.
//
// Besides radix-k, a binomial tree reduce to one root ("tree_reduce"): in round j the ranks whose
// lowest set bit (counted from the root) is j hand their whole frame to the rank 2^j below; one
// message at 2 ranks, but the frames grow towards the root, so it pays only for few ranks or
// sparse frames, and it cannot end in row bands.
//
// Everything here is a pure function of (p, radices, blocks): every rank computes the same plan
// without communication. Plain values; no MPI.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/composite/pixel_range.h"

namespace lantern {

struct CompositingSchedule {
  int ranks = 1;             // p
  std::vector<int> radices;  // k_1 .. k_m, each >= 2; their product is the base q (1 if empty)
  bool tree = false;         // a binomial tree reduce to the root instead (radices empty)

  int base() const;    // q
  int extras() const;  // p - q: groups holding two ranks
  // "binary_swap", "direct_send" or "radix_k 4x4x2", with " fold 3" when 3 ranks fold first;
  // "tree_reduce".
  std::string name() const;
  // A radix list is usable for p ranks when every k >= 2 and p / 2 <= q <= p; a tree has none.
  bool valid() const;

  // The group a rank belongs to, and the rank that represents a group in the rounds.
  int group_of(int rank) const;
  int base_rank(int group) const;
  // The rank folded into `group` first, or -1 if the group has one rank.
  int extra_rank(int group) const;
  bool is_extra(int rank) const { return rank != base_rank(group_of(rank)); }
};

// The schedules worth considering for p ranks: direct send, binary swap, radix-k with radices
// near 4, 8, 16, 32 and 64 in both orders, over the base p itself and, where p has a poor
// factorisation, over the largest power of two and the largest 2^a 3^b at most p (folding the
// rest); and, when the frame ends on one root, the tree reduce. Deterministic and duplicate-free.
// p >= 2.
std::vector<CompositingSchedule> candidate_schedules(int ranks, bool to_root);

// The q blocks of a frame of `pixels` pixels when the merged frame is to be gathered on one rank:
// equal contiguous shares.
std::vector<PixelRange> equal_blocks(size_t pixels, int groups);

// One rank's part in one round: for every other group of its round-group, the pixels it gives
// (to that group's base rank) and the pixels it keeps (received from it). `give[i]` goes to
// `partners[i]`; everything received is merged into `keep`.
struct RoundPlan {
  std::vector<int> partners;  // base ranks
  std::vector<PixelRange> give;
  PixelRange keep;
};

// What group `group` does in round `round` (0-based), over `blocks` (schedule.base() ranges,
// contiguous and in order).
RoundPlan round_plan(const CompositingSchedule &schedule, int group, int round,
                     const std::vector<PixelRange> &blocks);

}  // namespace lantern
