#include "triangle_bvh.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "clod/error.h"

namespace clod::detail {
namespace {

// Binary build tree, collapsed into 4-wide nodes afterwards.
struct BinaryNode {
  Aabb box;
  std::uint32_t left = 0, right = 0;  // children (inner node)
  std::uint32_t first = 0, count = 0; // primitive range (leaf: count > 0)
};

constexpr int kBinCount = 16;
// Past this binary depth the builder stops trusting SAH and splits at the object median, which
// bounds the depth by this plus log2(n) and so keeps traversal stacks fixed-size.
constexpr std::uint32_t kSahMaxDepth = 48;
constexpr std::uint32_t kParallelThreshold = 4096;

double halfArea(const Aabb& b) {
  if (b.empty()) return 0.0;
  const Vec3 e = b.extent();
  return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
}

class Builder {
public:
  Builder(std::span<const Aabb> boxes, std::uint32_t leafSize)
      : boxes_(boxes), leafSize_(std::max<std::uint32_t>(1, leafSize)), nodes_(2 * boxes.size()),
        order_(boxes.size()), centroids_(boxes.size()) {
    tbb::parallel_for(std::size_t(0), boxes.size(), [&](std::size_t i) {
      order_[i] = static_cast<std::uint32_t>(i);
      centroids_[i] = boxes[i].center();
    });
  }

  std::uint32_t build() { return buildRange(0, static_cast<std::uint32_t>(boxes_.size()), 1); }

  std::vector<BinaryNode>& nodes() { return nodes_; }
  std::vector<std::uint32_t>& order() { return order_; }
  std::uint32_t depth() const { return maxDepth_.load(); }

private:
  std::uint32_t allocate() { return nextNode_.fetch_add(1); }

  std::uint32_t buildRange(std::uint32_t first, std::uint32_t count, std::uint32_t depth) {
    const std::uint32_t index = allocate();
    BinaryNode& node = nodes_[index];
    Aabb centroidBox;
    for (std::uint32_t i = first; i < first + count; ++i) {
      node.box.extend(boxes_[order_[i]]);
      centroidBox.extend(centroids_[order_[i]]);
    }
    std::uint32_t seen = maxDepth_.load();
    while (depth > seen && !maxDepth_.compare_exchange_weak(seen, depth)) {
    }
    if (count <= leafSize_) {
      node.first = first;
      node.count = count;
      return index;
    }
    const std::uint32_t mid = split(first, count, centroidBox, depth);
    std::uint32_t left = 0, right = 0;
    if (count > kParallelThreshold) {
      tbb::parallel_invoke([&] { left = buildRange(first, mid - first, depth + 1); },
                           [&] { right = buildRange(mid, first + count - mid, depth + 1); });
    } else {
      left = buildRange(first, mid - first, depth + 1);
      right = buildRange(mid, first + count - mid, depth + 1);
    }
    nodes_[index].left = left;
    nodes_[index].right = right;
    return index;
  }

  // Returns the first position of the right half; both halves are non-empty.
  std::uint32_t split(std::uint32_t first, std::uint32_t count, const Aabb& centroidBox, std::uint32_t depth) {
    auto* begin = order_.data() + first;
    auto* end = begin + count;
    const Vec3 extent = centroidBox.extent();
    int axis = 0;
    if (extent.y() > extent[axis]) axis = 1;
    if (extent.z() > extent[axis]) axis = 2;
    auto medianSplit = [&](int ax) {
      auto* mid = begin + count / 2;
      std::nth_element(begin, mid, end, [&](std::uint32_t x, std::uint32_t y) {
        return centroids_[x][ax] < centroids_[y][ax];
      });
      return first + count / 2;
    };
    if (!(extent[axis] > 0.0) || depth > kSahMaxDepth) return medianSplit(axis);

    // Binned surface-area heuristic (Wald, "On fast construction of SAH-based bounding volume
    // hierarchies", 2007) over all three axes.
    double bestCost = std::numeric_limits<double>::infinity();
    int bestAxis = -1, bestBin = 0;
    for (int ax = 0; ax < 3; ++ax) {
      if (!(extent[ax] > 0.0)) continue;
      const double scale = kBinCount / extent[ax];
      Aabb bins[kBinCount];
      std::uint32_t binCounts[kBinCount] = {};
      for (auto* it = begin; it != end; ++it) {
        const int bin = std::min(kBinCount - 1, int((centroids_[*it][ax] - centroidBox.min[ax]) * scale));
        bins[bin].extend(boxes_[*it]);
        ++binCounts[bin];
      }
      double rightArea[kBinCount];
      std::uint32_t rightCount[kBinCount];
      Aabb acc;
      std::uint32_t n = 0;
      for (int b = kBinCount - 1; b > 0; --b) {
        acc.extend(bins[b]);
        n += binCounts[b];
        rightArea[b] = halfArea(acc);
        rightCount[b] = n;
      }
      acc = Aabb();
      n = 0;
      for (int b = 0; b < kBinCount - 1; ++b) {
        acc.extend(bins[b]);
        n += binCounts[b];
        if (n == 0 || rightCount[b + 1] == 0) continue;
        const double cost = halfArea(acc) * n + rightArea[b + 1] * rightCount[b + 1];
        if (cost < bestCost) {
          bestCost = cost;
          bestAxis = ax;
          bestBin = b;
        }
      }
    }
    if (bestAxis < 0) return medianSplit(axis);
    const double scale = kBinCount / extent[bestAxis];
    const double lo = centroidBox.min[bestAxis];
    auto* mid = std::partition(begin, end, [&](std::uint32_t i) {
      return std::min(kBinCount - 1, int((centroids_[i][bestAxis] - lo) * scale)) <= bestBin;
    });
    if (mid == begin || mid == end) return medianSplit(bestAxis);
    return first + static_cast<std::uint32_t>(mid - begin);
  }

  std::span<const Aabb> boxes_;
  std::uint32_t leafSize_;
  std::vector<BinaryNode> nodes_;
  std::vector<std::uint32_t> order_;
  std::vector<Vec3> centroids_;
  std::atomic<std::uint32_t> nextNode_{0};
  std::atomic<std::uint32_t> maxDepth_{0};
};

// Outward rounding: the float box must contain the double box.
float roundDown(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}
float roundUp(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

class Collapser {
public:
  Collapser(const std::vector<BinaryNode>& binary, std::vector<Bvh4Node>& out) : binary_(binary), out_(out) {}

  // Gathers up to four descendants of binary node `b` (opening the largest inner one each
  // time), emits them as one 4-wide node and recurses. Returns the new node's index.
  std::uint32_t collapse(std::uint32_t b) {
    std::uint32_t slots[4] = {binary_[b].left, binary_[b].right, 0, 0};
    int used = 2;
    while (used < 4) {
      int open = -1;
      double openArea = -1.0;
      for (int s = 0; s < used; ++s) {
        const BinaryNode& n = binary_[slots[s]];
        if (n.count == 0 && halfArea(n.box) > openArea) {
          openArea = halfArea(n.box);
          open = s;
        }
      }
      if (open < 0) break;
      const BinaryNode& n = binary_[slots[open]];
      slots[open] = n.left;
      slots[used++] = n.right;
    }
    const std::uint32_t index = static_cast<std::uint32_t>(out_.size());
    out_.emplace_back();
    for (int s = 0; s < 4; ++s) {
      Bvh4Node& node = out_[index];
      if (s >= used) {
        setEmpty(node, s);
        continue;
      }
      const BinaryNode& n = binary_[slots[s]];
      setBox(node, s, n.box);
      if (n.count > 0) {
        node.child[s] = n.first;
        node.count[s] = n.count;
      } else {
        node.count[s] = 0;
        const std::uint32_t child = collapse(slots[s]);
        out_[index].child[s] = child;  // out_ may have reallocated: index again
      }
    }
    return index;
  }

  // A tree whose root is a leaf still gets one node, with that leaf in slot 0.
  void emitRootLeaf(const BinaryNode& leaf) {
    out_.emplace_back();
    Bvh4Node& node = out_.back();
    setBox(node, 0, leaf.box);
    node.child[0] = leaf.first;
    node.count[0] = leaf.count;
    for (int s = 1; s < 4; ++s) setEmpty(node, s);
  }

private:
  static void setBox(Bvh4Node& node, int s, const Aabb& box) {
    node.minX[s] = roundDown(box.min.x());
    node.minY[s] = roundDown(box.min.y());
    node.minZ[s] = roundDown(box.min.z());
    node.maxX[s] = roundUp(box.max.x());
    node.maxY[s] = roundUp(box.max.y());
    node.maxZ[s] = roundUp(box.max.z());
  }
  static void setEmpty(Bvh4Node& node, int s) {
    const float inf = std::numeric_limits<float>::infinity();
    node.minX[s] = node.minY[s] = node.minZ[s] = inf;
    node.maxX[s] = node.maxY[s] = node.maxZ[s] = -inf;
    node.child[s] = Bvh4Node::kEmpty;
    node.count[s] = 0;
  }

  const std::vector<BinaryNode>& binary_;
  std::vector<Bvh4Node>& out_;
};

}  // namespace

TriangleBvh::TriangleBvh(std::span<const Aabb> boxes, const BvhBuildSettings& settings) {
  CLOD_ASSERT(!boxes.empty());
  Builder builder(boxes, settings.leafSize);
  const std::uint32_t root = builder.build();
  CLOD_ASSERT(root == 0);
  nodes_.reserve(boxes.size() / 2 + 1);
  Collapser collapser(builder.nodes(), nodes_);
  if (builder.nodes()[root].count > 0) {
    collapser.emitRootLeaf(builder.nodes()[root]);
  } else {
    collapser.collapse(root);
  }
  nodes_.shrink_to_fit();
  order_ = std::move(builder.order());
  depth_ = builder.depth();
  // Collapsing never deepens the tree, and the SAH depth cap bounds the binary depth.
  CLOD_ASSERT(depth_ <= kMaxDepth);
}

}  // namespace clod::detail
