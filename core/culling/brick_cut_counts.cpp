#include "core/culling/brick_cut_counts.h"

#include <algorithm>
#include <limits>

#include <glm/common.hpp>

namespace lantern {
namespace {

// Bricks per leaf of the hierarchy: a leaf's bricks are tested one by one. Small enough that a
// plane crossing a leaf tests few bricks it does not touch, large enough to keep the tree small.
constexpr uint32_t kLeafBricks = 8;

bool same_plane(const CutPlane &a, const CutPlane &b) {
  return a.normal == b.normal && a.offset == b.offset;
}

std::vector<CutPlane> enabled_planes(const std::vector<CutPlane> &cuts) {
  std::vector<CutPlane> out;
  for (const CutPlane &c : cuts)
    if (c.enabled) out.push_back(c);
  return out;
}

// Splits `from` against `to` as multisets: what only `from` has goes to *only_from, and what only
// `to` has to *only_to.
void plane_difference(const std::vector<CutPlane> &from, const std::vector<CutPlane> &to,
                      std::vector<CutPlane> *only_from, std::vector<CutPlane> *only_to) {
  std::vector<bool> matched(to.size(), false);
  for (const CutPlane &f : from) {
    bool found = false;
    for (size_t j = 0; j < to.size() && !found; ++j)
      if (!matched[j] && same_plane(f, to[j])) matched[j] = found = true;
    if (!found) only_from->push_back(f);
  }
  for (size_t j = 0; j < to.size(); ++j)
    if (!matched[j]) only_to->push_back(to[j]);
}

}  // namespace

uint32_t BrickCutCounts::build_node(const BrickSet &bricks, uint32_t first, uint32_t last) {
  const auto index = uint32_t(nodes_.size());
  nodes_.emplace_back();
  Node node;
  node.first = first;
  node.last = last;
  if (last - first > kLeafBricks) {
    const uint32_t middle = first + (last - first) / 2;
    node.left = build_node(bricks, first, middle);
    node.right = build_node(bricks, middle, last);
    node.lo = glm::min(nodes_[node.left].lo, nodes_[node.right].lo);
    node.hi = glm::max(nodes_[node.left].hi, nodes_[node.right].hi);
  } else {
    node.lo = glm::dvec3(std::numeric_limits<double>::infinity());
    node.hi = -node.lo;
    for (uint32_t i = first; i < last; ++i) {
      node.lo = glm::min(node.lo, bricks.bricks[i].lo);
      node.hi = glm::max(node.hi, bricks.bricks[i].hi);
    }
  }
  nodes_[index] = node;
  return index;
}

void BrickCutCounts::build_hierarchy(const BrickSet &bricks) {
  nodes_.clear();
  const auto n = uint32_t(bricks.bricks.size());
  if (n > 0) build_node(bricks, 0, n);
}

void BrickCutCounts::apply(const BrickSet &bricks, const CutPlanes::Plane &plane, int delta) {
  using Side = CutPlanes::Side;
  if (nodes_.empty()) return;
  const auto add = [delta](uint32_t *counter) { *counter = uint32_t(int64_t(*counter) + delta); };
  std::vector<uint32_t> stack{0};
  while (!stack.empty()) {
    const Node &node = nodes_[stack.back()];
    stack.pop_back();
    // A node's box holds its bricks' boxes and the test is monotone in the box, so a whole
    // node kept or dropped means each of its bricks is, by the very same test.
    const Side whole = CutPlanes::classify_box(plane, node.lo, node.hi);
    if (whole == Side::kKept) continue;
    if (whole == Side::kDropped) {
      for (uint32_t i = node.first; i < node.last; ++i) add(&dropped_[i]);
      continue;
    }
    if (node.left != 0) {
      stack.push_back(node.right);
      stack.push_back(node.left);
      continue;
    }
    for (uint32_t i = node.first; i < node.last; ++i) {
      const Brick &b = bricks.bricks[i];
      const Side side = CutPlanes::classify_box(plane, b.lo, b.hi);
      if (side == Side::kDropped) add(&dropped_[i]);
      if (side == Side::kBoth) add(&crossed_[i]);
    }
    last_.bricks_tested += node.last - node.first;
  }
}

void BrickCutCounts::update(const BrickSet &bricks, const std::vector<CutPlane> &cuts) {
  last_ = Update();
  const std::vector<CutPlane> wanted = enabled_planes(cuts);
  std::vector<CutPlane> removed, added;
  if (bricks.generation == 0 || bricks.generation != generation_ ||
      dropped_.size() != bricks.bricks.size()) {
    last_.from_scratch = true;
    generation_ = bricks.generation;
    dropped_.assign(bricks.bricks.size(), 0);
    crossed_.assign(bricks.bricks.size(), 0);
    build_hierarchy(bricks);
    applied_.clear();
    added = wanted;
  } else {
    plane_difference(applied_, wanted, &removed, &added);
  }
  for (const CutPlane &c : removed) apply(bricks, CutPlanes::plane_of(c), -1);
  for (const CutPlane &c : added) apply(bricks, CutPlanes::plane_of(c), +1);
  last_.planes_removed = int(removed.size());
  last_.planes_added = int(added.size());
  applied_ = wanted;
}

}  // namespace lantern
