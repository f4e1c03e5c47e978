#include "top_down_build.h"

#include <algorithm>

#include <tbb/parallel_for.h>

#include "clod/error.h"

namespace clod::detail {
namespace {

void growToCover(BuildNode& node, double slack) {
  double r = node.sphere.radius;
  for (const SurfacePiece& piece : node.pieces) r = std::max(r, farthestDistance(node.sphere.center, piece.points()));
  node.sphere.radius = r + slack;
}

// Appends one level's spheres (parents filled in by the caller) and their triangle lists.
void appendLevel(SphereTree& tree, const std::vector<BuildNode>& nodes, const std::vector<std::uint32_t>& parents) {
  std::vector<std::vector<std::uint32_t>> lists(nodes.size());
  tbb::parallel_for(std::size_t{0}, nodes.size(), [&](std::size_t i) {
    auto& list = lists[i];
    list.reserve(nodes[i].pieces.size());
    for (const SurfacePiece& piece : nodes[i].pieces) list.push_back(piece.triangle);
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  });
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const Sphere& s = nodes[i].sphere;
    tree.centerX.push_back(s.center.x());
    tree.centerY.push_back(s.center.y());
    tree.centerZ.push_back(s.center.z());
    tree.radius.push_back(s.radius);
    tree.parent.push_back(parents[i]);
    tree.firstChild.push_back(kNoSphere);
    tree.childCount.push_back(0);
    tree.triangleList.insert(tree.triangleList.end(), lists[i].begin(), lists[i].end());
    tree.triangleOffsets.push_back(static_cast<std::uint32_t>(tree.triangleList.size()));
  }
  tree.levelOffsets.push_back(static_cast<std::uint32_t>(tree.radius.size()));
}

}  // namespace

SphereTree buildTopDown(const TriangleMesh& mesh, BuildNode root, std::uint32_t depth, std::uint32_t branching,
                        const SplitNode& split) {
  const double slack = kCoverageSlackRel * mesh.bounds().diagonal();
  SphereTree tree;
  tree.levelOffsets.push_back(0);
  tree.triangleOffsets.push_back(0);

  growToCover(root, slack);
  std::vector<BuildNode> level;
  level.push_back(std::move(root));
  appendLevel(tree, level, {kNoSphere});

  for (std::uint32_t l = 0; l < depth; ++l) {
    std::vector<std::vector<BuildNode>> children(level.size());
    tbb::parallel_for(std::size_t{0}, level.size(), [&](std::size_t i) {
      split(level[i], l, static_cast<std::uint32_t>(i), children[i]);
      CLOD_ASSERT(!children[i].empty() && children[i].size() <= branching);
      for (BuildNode& child : children[i]) {
        CLOD_ASSERT(!child.pieces.empty());
        growToCover(child, slack);
      }
    });
    const std::uint32_t parentBegin = tree.levelBegin(l);
    std::vector<BuildNode> next;
    std::vector<std::uint32_t> parents;
    for (std::size_t i = 0; i < level.size(); ++i) {
      const std::uint32_t p = parentBegin + static_cast<std::uint32_t>(i);
      tree.firstChild[p] = tree.sphereCount() + static_cast<std::uint32_t>(next.size());
      tree.childCount[p] = static_cast<std::uint32_t>(children[i].size());
      for (BuildNode& child : children[i]) {
        next.push_back(std::move(child));
        parents.push_back(p);
      }
    }
    level = std::move(next);
    appendLevel(tree, level, parents);
  }
  return tree;
}

}  // namespace clod::detail
