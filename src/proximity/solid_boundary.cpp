#include "clod/solid_boundary.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "clod/error.h"

namespace clod {
namespace {

using Corners = std::array<Vec3, 3>;

// Just off a face, the face's own solid angle contributes +-1/2 and every other face about what
// it contributes at the face, w_o: behind the face w = w_o + 1/2, in front w_o - 1/2. On the
// boundary of one closed part w_o = 1/2 (0 and 1); inside another closed part w_o >= 3/2 (1
// and 2): a margin of 1/2 either way, which the hierarchical winding number's error (< 0.1,
// proximity.h) does not reach.
bool solidOnBothSides(const MeshDistance& distance, const Vec3& p, const Vec3& offset) {
  return distance.windingNumber(p + offset) >= 0.5 && distance.windingNumber(p - offset) >= 0.5;
}

enum class Verdict { kBoundary, kInterior, kMixed };

Verdict classify(const MeshDistance& distance, const Corners& t, const Vec3& offset) {
  const Vec3 centroid = (t[0] + t[1] + t[2]) / 3.0;
  const bool first = solidOnBothSides(distance, centroid, offset);
  for (const Vec3& corner : t)
    if (solidOnBothSides(distance, centroid + 0.8 * (corner - centroid), offset) != first) return Verdict::kMixed;
  return first ? Verdict::kInterior : Verdict::kBoundary;
}

double longestEdge(const Corners& t) {
  return std::sqrt(std::max({(t[1] - t[0]).squaredNorm(), (t[2] - t[1]).squaredNorm(), (t[0] - t[2]).squaredNorm()}));
}

// The pieces of one face that bound the solid, by midpoint subdivision. Returns true when the
// whole face does (no piece was dropped or split to resolution).
struct FaceSplitter {
  const MeshDistance& distance;
  double resolution, sampleSpacing;
  Vec3 offset;
  std::vector<Corners>& pieces;
  std::uint32_t splitsLeft;  // bounds the work and the pieces of one face (hostile soups)

  bool keep(const Corners& t) {
    const double edge = longestEdge(t);
    if (edge <= sampleSpacing) {
      const Verdict v = classify(distance, t, offset);
      if (v == Verdict::kInterior) return false;
      // Out of splits, a mixed piece is kept: a wall left in costs field quality, a hole the sign.
      if (v == Verdict::kBoundary || edge <= resolution || splitsLeft == 0) {
        pieces.push_back(t);
        return v == Verdict::kBoundary;
      }
      --splitsLeft;
    }
    const Vec3 m01 = 0.5 * (t[0] + t[1]), m12 = 0.5 * (t[1] + t[2]), m20 = 0.5 * (t[2] + t[0]);
    bool whole = keep({t[0], m01, m20});
    whole &= keep({m01, t[1], m12});
    whole &= keep({m20, m12, t[2]});
    whole &= keep({m01, m12, m20});
    return whole;
  }
};

}  // namespace

SolidBoundary solidBoundary(const MeshDistance& distance, double resolution, double sampleSpacing) {
  if (!(resolution > 0.0 && resolution <= sampleSpacing && std::isfinite(sampleSpacing)))
    throw Error(ErrorCode::kInvalidArgument, "solidBoundary: need 0 < resolution (" + std::to_string(resolution) +
                                                 ") <= sampleSpacing (" + std::to_string(sampleSpacing) + ")");
  const TriangleMesh& mesh = distance.mesh();
  const Aabb box = mesh.bounds();
  // The sample points only have to stay off their face and nearer to it than to any other.
  const double offsetLength = 1e-6 * box.diagonal();

  // The work is classifications, 8 winding numbers each. The coarse sampling makes about
  // 2 area / spacing^2 of them: a soup with more surface than 2^17 such pieces is sampled
  // coarser. Each split of a mixed piece makes 4 more: a face gets up to 2^16 / T splits, at
  // least 16. So a soup of many large crossing faces stays O(2^17 + T) classifications.
  double area = 0.0;
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) area += 0.5 * mesh.triangleCross(t).norm();
  sampleSpacing = std::max(sampleSpacing, std::sqrt(2.0 * area / double(1u << 17)));
  const std::uint32_t splitsPerFace = std::max<std::uint32_t>(16, (1u << 16) / std::max<std::uint32_t>(1, mesh.triangleCount()));
  enum : std::uint8_t { kWhole, kDropped, kSplit };
  std::vector<std::uint8_t> fate(mesh.triangleCount(), kWhole);
  std::vector<std::vector<Corners>> pieces(mesh.triangleCount());
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, mesh.triangleCount(), 16), [&](const auto& range) {
    for (std::uint32_t t = range.begin(); t != range.end(); ++t) {
      const Vec3 cross = mesh.triangleCross(t);
      const double twiceArea = cross.norm();
      if (twiceArea == 0.0) continue;
      // A sliver's samples lie close to its neighbours: stay much nearer than its width.
      const Vec3 offset = std::min(offsetLength, 1e-3 * std::sqrt(twiceArea)) / twiceArea * cross;
      FaceSplitter splitter{distance, resolution, sampleSpacing, offset, pieces[t], splitsPerFace};
      if (splitter.keep({mesh.corner(t, 0), mesh.corner(t, 1), mesh.corner(t, 2)})) {
        pieces[t].clear();
        pieces[t].shrink_to_fit();
      } else {
        fate[t] = pieces[t].empty() ? kDropped : kSplit;
      }
    }
  });

  SolidBoundary out;
  out.mesh.vertices = mesh.vertices;
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) {
    if (fate[t] == kWhole) {
      out.mesh.triangles.push_back(mesh.triangles[t]);
      continue;
    }
    ++(fate[t] == kDropped ? out.droppedTriangles : out.splitTriangles);
    for (const Corners& piece : pieces[t]) {
      const auto first = out.mesh.vertexCount();
      out.mesh.vertices.insert(out.mesh.vertices.end(), piece.begin(), piece.end());
      out.mesh.triangles.push_back({first, first + 1, first + 2});
    }
  }
  return out;
}

}  // namespace clod
