#include "core/composite/active_pixel_compositing.h"

namespace lantern {
namespace {

// One tag per phase ("LP"...): a rank that has moved on to the next phase never has its
// messages taken for the current one's.
constexpr int kFoldTag = 0x4c50;
constexpr int kRoundTag = kFoldTag + 1;
constexpr int kFinishTag = kFoldTag + 2;

}  // namespace

Status run_active_pixel_plan(MPI_Comm comm, const ActivePixelPlan &plan, ActiveFrame &frame,
                             ActivePixelScratch &scratch, CompositeTraffic *traffic) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const CompositingSchedule &s = plan.schedule;
  const int group = s.group_of(rank);
  const int base = s.base_rank(group), extra = s.extra_rank(group);
  const PixelRange whole{0, frame.frame->pixel_count()};
  Status first_error;
  // `streams`: the phase's stream count from the plan, the same on every rank, so that both ends
  // of every stream bound its messages alike (active_pixel_exchange.h).
  const auto run = [&](int tag, size_t streams, const std::vector<OutgoingRange> &out,
                       const std::vector<IncomingRange> &in) {
    Status st = exchange_active_pixels(comm, tag, streams, out, in, frame, scratch, traffic);
    if (first_error.ok()) first_error = std::move(st);
  };

  if (s.tree) {
    // Binomial tree to the root, ranks counted from it: v hands its frame to v - 2^j in the round
    // of its lowest set bit j, after taking those of v + 2^i for every i < j.
    int ranks = 1;
    MPI_Comm_size(comm, &ranks);
    const int v = (rank - plan.root + ranks) % ranks;
    const auto actual = [&](int u) { return (u + plan.root) % ranks; };
    for (int bit = 1; bit < ranks && first_error.code != StatusCode::kMpi; bit <<= 1) {
      if (v & bit) {
        run(kRoundTag, 1, {{actual(v - bit), whole}}, {});
        break;
      }
      if (v + bit < ranks) run(kRoundTag, 1, {}, {{actual(v + bit), whole}});
    }
    return first_error;
  }

  // Fold: an extra rank's whole frame into its base rank.
  if (rank != base) {
    run(kFoldTag, 1, {{base, whole}}, {});
  } else if (extra >= 0) {
    run(kFoldTag, 1, {}, {{extra, whole}});
  }

  // Rounds, among the base ranks.
  if (rank == base) {
    // A malformed message does not stop the protocol; an MPI failure does (as in the dense
    // methods).
    for (int round = 0; round < int(s.radices.size()) && first_error.code != StatusCode::kMpi;
         ++round) {
      const RoundPlan r = round_plan(s, group, round, plan.blocks);
      std::vector<OutgoingRange> out;
      std::vector<IncomingRange> in;
      for (size_t i = 0; i < r.partners.size(); ++i) {
        out.push_back({r.partners[i], r.give[i]});
        in.push_back({r.partners[i], r.keep});
      }
      run(kRoundTag, size_t(s.radices[size_t(round)] - 1), out, in);
    }
  }

  // Finish. The receiver merges rather than overwrites: every value a rank holds is a minimum over
  // some ranks, so its stale pixels there are never nearer than the final ones, and where nothing
  // comes (the final pixel is empty) they are empty already. A failed MPI call is fatal under
  // MPI's default error handler; with MPI_ERRORS_RETURN this phase still runs so that no rank is
  // left waiting in it.
  // To a root, the root receives up to q streams (q - 1 when it is a base rank itself) while each
  // sender sends one: the root's count bounds every stream. Bands: one stream per extra rank.
  std::vector<OutgoingRange> out;
  std::vector<IncomingRange> in;
  const size_t finish_streams = plan.bands.empty() ? size_t(s.base()) : 1;
  if (plan.bands.empty()) {
    if (rank == base && rank != plan.root) out.push_back({plan.root, plan.blocks[size_t(group)]});
    if (rank == plan.root)
      for (int g = 0; g < s.base(); ++g)
        if (s.base_rank(g) != rank) in.push_back({s.base_rank(g), plan.blocks[size_t(g)]});
  } else if (rank == base && extra >= 0) {
    out.push_back({extra, plan.bands[size_t(extra)]});
  } else if (rank != base) {
    in.push_back({base, plan.bands[size_t(rank)]});
  }
  run(kFinishTag, finish_streams, out, in);
  return first_error;
}

}  // namespace lantern
