#include "core/culling/column_strips.h"

#include "core/bricks/radix_sort.h"

namespace lantern {

void merge_strips(const VisibleBricks &visible, const BrickSet &bricks, std::vector<StripState> *s,
                  int count, PageVector<uint64_t> *scratch, CullStats *st, DrawList *out) {
  // Union of what any strip shows (a particle two strips show appears twice: same entry). One
  // strip's list becomes the output as it is, the others' are copied; then every strip's list is
  // released: the strips are per-frame scratch (a list holds every sphere its strip drew, 2 MiB
  // for 260 k), kept between frames only in the merged output.
  const auto merge = [&](auto list, PageVector<uint64_t> *merged) {
    merged->clear();
    if (count == 1) {
      merged->swap(list((*s)[0]));
    } else {
      for (int k = 0; k < count; ++k) {
        const PageVector<uint64_t> &l = list((*s)[size_t(k)]);
        merged->insert(merged->end(), l.begin(), l.end());
      }
    }
    for (int k = 0; k < count; ++k) PageVector<uint64_t>().swap(list((*s)[size_t(k)]));
    radix_sort_words(merged, scratch, 32, 64);
    merged->erase(std::unique(merged->begin(), merged->end()), merged->end());
  };
  merge([](StripState &x) -> PageVector<uint64_t> & { return x.out.spheres; }, &out->spheres);
  merge([](StripState &x) -> PageVector<uint64_t> & { return x.out.points; }, &out->points);
  int64_t judged = 0;
  for (size_t k = 0; k < visible.size(); ++k) {
    const VisibleBrick &v = visible[k];
    st->lod_dropped += bricks.bricks[v.brick].count - v.keep;
    int i = 0;
    while (i < count && (*s)[size_t(i)].frustum_pp[k] < 0) ++i;
    if (i == count) {
      ++st->bricks_occluded;
      st->occlusion_culled += v.keep;
      continue;
    }
    const StripState &strip = (*s)[size_t(i)];
    st->frustum_culled += strip.frustum_pp[k];
    st->cut_culled += strip.cut_pp[k];
    judged += v.keep - strip.frustum_pp[k] - strip.cut_pp[k];
  }
  st->occlusion_culled += judged - int64_t(out->spheres.size() + out->points.size());
}

}  // namespace lantern
