#include "core/culling/column_strips.h"

#include "core/bricks/radix_sort.h"

namespace lantern {

void merge_strips(const std::vector<VisibleBrick> &visible, const BrickSet &bricks,
                  const StripState s[2], std::vector<uint64_t> *scratch, CullStats *st,
                  DrawList *out) {
  // Union of what either strip shows (a particle both show appears twice: same entry).
  const auto merge = [scratch](const std::vector<uint64_t> &a, const std::vector<uint64_t> &b,
                               std::vector<uint64_t> *merged) {
    *merged = a;
    merged->insert(merged->end(), b.begin(), b.end());
    radix_sort_words(merged, scratch, 32, 64);
    merged->erase(std::unique(merged->begin(), merged->end()), merged->end());
  };
  merge(s[0].out.spheres, s[1].out.spheres, &out->spheres);
  merge(s[0].out.points, s[1].out.points, &out->points);
  int64_t judged = 0;
  for (size_t k = 0; k < visible.size(); ++k) {
    const VisibleBrick &v = visible[k];
    st->lod_dropped += bricks.bricks[v.brick].count - v.keep;
    const int i = s[0].frustum_pp[k] >= 0 ? 0 : s[1].frustum_pp[k] >= 0 ? 1 : -1;
    if (i < 0) {
      ++st->bricks_occluded;
      st->occlusion_culled += v.keep;
      continue;
    }
    st->frustum_culled += s[i].frustum_pp[k];
    st->cut_culled += s[i].cut_pp[k];
    judged += v.keep - s[i].frustum_pp[k] - s[i].cut_pp[k];
  }
  st->occlusion_culled += judged - int64_t(out->spheres.size() + out->points.size());
}

}  // namespace lantern
