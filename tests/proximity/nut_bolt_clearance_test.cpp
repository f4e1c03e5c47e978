#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>

#include <gtest/gtest.h>

#include "clod/math.h"
#include "clod/proximity.h"
#include "clod/thread_meshes.h"

// The nut-on-bolt scene's start pose (thread_meshes.h, scenes/nut_bolt.json) checked with exact
// distances: here rather than in tests/mesh because the oracle is the proximity layer's.
namespace clod {
namespace {

class ThreadMeshParts : public ::testing::Test {
protected:
  const NutBoltParts parts{};
  const std::vector<NamedMesh> meshes = nutBoltMeshes(parts);
  const TriangleMesh& bolt = meshes[0].mesh;
  const TriangleMesh& nut = meshes[1].mesh;
};

// Lower bound on the distance from every point of `surface` (placed by xf) to the solid
// `other`, proven by recursive subdivision: the signed distance to a closed mesh is 1-Lipschitz,
// so a triangle whose centroid lies at signed distance d outside `other` and whose corners are
// all within R of that centroid has every point outside `other` and at least d - R away when
// d > R. A triangle with d - R below `target` is split in four, at most `depthLimit` times; the
// result is the smallest d - R of the pieces reached (>= target: proven; negative: not proven).
double provenClearance(const TriangleMesh& surface, const Pose& xf, const MeshDistance& other, int depthLimit,
                       double target = 0.0) {
  double lowest = 1e9;
  std::function<void(const Vec3&, const Vec3&, const Vec3&, int)> visit = [&](const Vec3& a, const Vec3& b,
                                                                            const Vec3& c, int depth) {
    const Vec3 centroid = (a + b + c) / 3.0;
    const double reach = std::max({(a - centroid).norm(), (b - centroid).norm(), (c - centroid).norm()});
    const double d = other.signedDistance(centroid);
    if (d - reach >= target) {
      lowest = std::min(lowest, d - reach);
      return;
    }
    if (depth == depthLimit) {
      lowest = std::min(lowest, d - reach);  // unproven: negative or too close to tell
      return;
    }
    const Vec3 ab = 0.5 * (a + b), bc = 0.5 * (b + c), ca = 0.5 * (c + a);
    visit(a, ab, ca, depth + 1);
    visit(ab, b, bc, depth + 1);
    visit(ca, bc, c, depth + 1);
    visit(ab, bc, ca, depth + 1);
  };
  for (std::uint32_t t = 0; t < surface.triangleCount(); ++t)
    visit(xf.apply(surface.corner(t, 0)), xf.apply(surface.corner(t, 1)), xf.apply(surface.corner(t, 2)), 0);
  return lowest;
}

// The scene's start pose: the nut (placed at z = (boltTurns - 1) pitches, unturned) engages the
// bolt's last turn. Every point of each surface is proven outside the other solid, so the solids
// do not overlap, and the gap is at least a third of the flank gap of the smooth threads
// (clearance x sin 30 degrees = 75 um): the facets (chords 0.07 mm inside the circles at the
// crest) eat into it where a vertex of one part meets the middle of the other's facet. Also at a
// half-segment turn, where the facets are most out of step.
TEST_F(ThreadMeshParts, NutOnTheFirstThreadDoesNotOverlapTheBolt) {
  const double p = parts.thread.pitch;
  const MeshDistance boltDistance(bolt), nutDistance(nut);
  for (const double turn : {0.0, 0.5}) {
    const double angle = 2 * std::numbers::pi * turn / parts.segmentsPerTurn;
    Pose xfNut;
    xfNut.rotation = Quat(Eigen::AngleAxisd(angle, Vec3::UnitZ()));
    xfNut.translation = Vec3(0, 0, (parts.boltTurns - 1) * p + p * turn / parts.segmentsPerTurn);
    const double flankGap = parts.radialClearance * 0.5;
    const double nutClear = provenClearance(nut, xfNut, boltDistance, 12, flankGap / 3);
    const double boltClear = provenClearance(bolt, xfNut.inverse(), nutDistance, 12, flankGap / 3);
    EXPECT_GT(nutClear, flankGap / 3) << "turn " << turn;
    EXPECT_GT(boltClear, flankGap / 3) << "turn " << turn;
    // ... and the nut is engaged: moved down by the flank gap's axial length x 3 it overlaps.
    xfNut.translation.z() -= 3 * parts.radialClearance * std::tan(std::numbers::pi / 6);
    EXPECT_LT(provenClearance(nut, xfNut, boltDistance, 0), 0.0);
  }
}

}  // namespace
}  // namespace clod
