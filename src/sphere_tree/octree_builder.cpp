#include "octree_builder.h"

#include <array>

#include "top_down_build.h"

namespace clod::detail {
namespace {

std::array<int, 3> gridSplit(const Vec3& extent, std::uint32_t branching) {
  std::array<int, 3> n{1, 1, 1};
  for (;;) {
    int best = -1;
    double bestSize = -1.0;
    for (int a = 0; a < 3; ++a) {
      const std::uint32_t product = static_cast<std::uint32_t>((n[0] * n[1] * n[2] / n[a]) * (n[a] + 1));
      const double size = extent[a] / n[a];
      if (product <= branching && size > bestSize) {
        best = a;
        bestSize = size;
      }
    }
    if (best < 0) return n;
    ++n[best];
  }
}

}  // namespace

SphereTree buildOctreeSphereTree(const TriangleMesh& mesh, const SphereTreeSettings& settings) {
  const Aabb box = mesh.bounds();
  BuildNode root;
  // The root cell is the cube around the bounding box (Hubbard's octree is cubic).
  const double half = 0.5 * box.extent().maxCoeff();
  root.cellLo = box.center() - Vec3::Constant(half);
  root.cellHi = box.center() + Vec3::Constant(half);
  root.pieces.reserve(mesh.triangleCount());
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) root.pieces.push_back(makeTrianglePiece(mesh, t));
  std::vector<Vec3> scratch;
  root.sphere = minimumEnclosingSphere(mesh.vertices, scratch);

  const std::uint32_t branching = settings.branching;
  auto split = [branching](const BuildNode& parent, std::uint32_t, std::uint32_t, std::vector<BuildNode>& children) {
    const Vec3 extent = parent.cellHi - parent.cellLo;
    const std::array<int, 3> n = gridSplit(extent, branching);
    const int cellCount = n[0] * n[1] * n[2];
    std::vector<BuildNode> cells(static_cast<std::size_t>(cellCount));
    const Vec3 step(extent.x() / n[0], extent.y() / n[1], extent.z() / n[2]);
    auto cellIndex = [&](int i, int j, int k) { return (k * n[1] + j) * n[0] + i; };
    for (int k = 0; k < n[2]; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i) {
          BuildNode& cell = cells[static_cast<std::size_t>(cellIndex(i, j, k))];
          const std::array<int, 3> idx{i, j, k};
          for (int a = 0; a < 3; ++a) {
            // Shared faces get the same coordinate bit for bit on both sides; the outer
            // faces are the parent's own, so no piece can fall through a gap.
            cell.cellLo[a] = idx[a] == 0 ? parent.cellLo[a] : parent.cellLo[a] + idx[a] * step[a];
            cell.cellHi[a] = idx[a] + 1 == n[a] ? parent.cellHi[a] : parent.cellLo[a] + (idx[a] + 1) * step[a];
          }
        }
    for (const SurfacePiece& piece : parent.pieces) {
      const Aabb pb = piece.bounds();
      bool placed = false;
      for (BuildNode& cell : cells) {
        if ((pb.max.array() < cell.cellLo.array()).any() || (pb.min.array() > cell.cellHi.array()).any()) continue;
        SurfacePiece part = clipPieceToBox(piece, cell.cellLo, cell.cellHi);
        if (keepClippedPart(part, piece)) {
          cell.pieces.push_back(part);
          placed = true;
        }
      }
      if (!placed) {
        // Only rounding can get here (the cells tile the parent): keep the piece whole in the
        // cell of its centroid, which keeps coverage exact.
        const Vec3 c = piece.centroid();
        int best = 0;
        double bestDistance = 1e300;
        for (int ci = 0; ci < cellCount; ++ci) {
          const BuildNode& cell = cells[static_cast<std::size_t>(ci)];
          const double d = (c - 0.5 * (cell.cellLo + cell.cellHi)).squaredNorm();
          if (d < bestDistance) {
            bestDistance = d;
            best = ci;
          }
        }
        cells[static_cast<std::size_t>(best)].pieces.push_back(piece);
      }
    }
    std::vector<Vec3> points;
    std::vector<Vec3> scratchPoints;
    for (BuildNode& cell : cells) {
      if (cell.pieces.empty()) continue;
      points.clear();
      for (const SurfacePiece& piece : cell.pieces) points.insert(points.end(), piece.points().begin(), piece.points().end());
      cell.sphere = minimumEnclosingSphere(points, scratchPoints);
      children.push_back(std::move(cell));
    }
  };
  return buildTopDown(mesh, std::move(root), settings.depth, settings.branching, split);
}

}  // namespace clod::detail
