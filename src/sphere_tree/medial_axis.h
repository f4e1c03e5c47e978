#pragma once
// An approximate medial axis from surface samples: the Voronoi vertices of the samples (the
// circumcentres of their Delaunay tetrahedra, computed with qhull) that lie inside the object
// approximate the medial axis, and each such vertex with the distance to its four samples is a
// medial sphere (Hubbard 1996; Amenta, Choi & Kolluri 2001 "The power crust" for the poles).

#include <cstdint>
#include <vector>

#include "clod/math.h"
#include "clod/mesh.h"

namespace clod::detail {

struct SurfaceSamples {
  std::vector<Vec3> position;
  std::vector<Vec3> normal;  ///< outward unit normal of the triangle (or vertex) sampled
  /// Inner pole of each sample: the centre and radius of the largest interior medial sphere
  /// that touches it. Samples without one get their own position and radius 0.
  std::vector<Vec3> poleCenter;
  std::vector<double> poleRadius;
  /// Identifies the pole: samples with the same interior medial sphere share an id; samples
  /// without a pole keep their own index; poles are numbered from size() on.
  std::vector<std::uint32_t> poleId;
  std::uint32_t size() const { return static_cast<std::uint32_t>(position.size()); }
};

/// Area-weighted random samples (deterministic for a given seed; about `target` of them) plus
/// every mesh vertex when there are at most `target` vertices, so sharp corners are present.
SurfaceSamples sampleSurface(const TriangleMesh& mesh, std::uint32_t target, std::uint32_t seed);

/// Fills poleCenter / poleRadius from the Delaunay tetrahedralisation of the samples.
/// A Voronoi vertex counts as interior when the outward normals of its four samples point away
/// from it on balance (sum of the signs of (centre - sample) . normal < 0); this needs only a
/// consistently oriented surface, so it also works for open meshes. If qhull cannot
/// tetrahedralise the samples (all in one plane: a flat mesh), no sample gets a pole.
void computeInnerPoles(SurfaceSamples& samples, const Aabb& bounds);

/// Uniform grid over sample positions for nearest-sample queries.
class SampleGrid {
public:
  SampleGrid(const std::vector<Vec3>& positions, double cellSize);
  /// Index of the sample nearest to p (the set must be non-empty).
  std::uint32_t nearest(const Vec3& p) const;

private:
  const std::vector<Vec3>* positions_;
  Vec3 origin_;
  double cellSize_;
  std::int32_t dims_[3];
  std::vector<std::uint32_t> cellStart_;
  std::vector<std::uint32_t> items_;
};

}  // namespace clod::detail
