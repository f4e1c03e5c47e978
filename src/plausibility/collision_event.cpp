// First collision of a recorded trajectory, and the surface gap of two placed meshes.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "clod/error.h"

#include "clod/plausibility.h"

namespace clod {

CollisionEvent findFirstCollision(std::span<const TrajectoryFrame> frames, std::size_t settleFrames) {
  CollisionEvent e;
  const auto first = std::find_if(frames.begin(), frames.end(), [](const TrajectoryFrame& f) { return f.contact; });
  if (first == frames.end()) return e;
  e.found = true;
  e.firstContact = static_cast<std::size_t>(first - frames.begin());
  e.contactEnd = e.firstContact;
  while (e.contactEnd < frames.size() && frames[e.contactEnd].contact) ++e.contactEnd;
  e.post = std::min(e.contactEnd + settleFrames, frames.size() - 1);
  for (std::size_t i = e.firstContact; i < e.contactEnd; ++i) {
    const double g = frames[i].gap;
    if (std::isnan(g)) continue;
    e.minGap = std::isnan(e.minGap) ? g : std::min(e.minGap, g);
  }
  return e;
}

namespace {
// Smallest unsigned distance from the edges of `from` (placed by xfWorldFromFrom) to `to`'s
// surface, to within toleranceAbs, starting from the bound `best`. The distance to a surface is
// 1-Lipschitz along a segment, so on a segment of length L with end distances f0, f1 it is at
// least (f0 + f1 - L) / 2: a segment whose bound cannot beat `best` by the tolerance is dropped,
// any other is halved (branch and bound).
double minEdgeDistance(const MeshDistance& from, const Pose& xfWorldFromFrom, const MeshDistance& to,
                       const Pose& xfWorldFromTo, double toleranceAbs, double best) {
  const Pose xfToFromFrom = xfWorldFromTo.inverse() * xfWorldFromFrom;
  const TriangleMesh& mesh = from.mesh();
  std::vector<Vec3> p(mesh.vertices.size());
  std::vector<double> f(mesh.vertices.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    p[i] = xfToFromFrom.apply(mesh.vertices[i]);
    f[i] = to.closestPoint(p[i]).distance;
    best = std::min(best, f[i]);
  }
  struct Segment {
    Vec3 a, b;
    double fa, fb;
  };
  std::vector<Segment> stack;
  for (const auto& t : mesh.triangles) {
    // Within the tolerance of touching: nothing can improve the answer by more than it.
    if (best <= toleranceAbs) return best;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t i = t[k], j = t[(k + 1) % 3];
      stack.push_back({p[i], p[j], f[i], f[j]});
      while (!stack.empty()) {
        const Segment s = stack.back();
        stack.pop_back();
        const double length = (s.b - s.a).norm();
        if (0.5 * (s.fa + s.fb - length) >= best - toleranceAbs || length <= toleranceAbs) continue;
        const Vec3 mid = 0.5 * (s.a + s.b);
        const double fm = to.closestPoint(mid).distance;
        best = std::min(best, fm);
        stack.push_back({s.a, mid, s.fa, fm});
        stack.push_back({mid, s.b, fm, s.fb});
      }
    }
  }
  return best;
}
}  // namespace

double surfaceGap(const MeshDistance& a, const Pose& xfWorldFromA, const MeshDistance& b, const Pose& xfWorldFromB,
                  double toleranceAbs) {
  CLOD_ASSERT(toleranceAbs > 0.0 && std::isfinite(toleranceAbs));
  const double ab = minEdgeDistance(a, xfWorldFromA, b, xfWorldFromB, toleranceAbs, std::numeric_limits<double>::infinity());
  return minEdgeDistance(b, xfWorldFromB, a, xfWorldFromA, toleranceAbs, ab);
}

}  // namespace clod
