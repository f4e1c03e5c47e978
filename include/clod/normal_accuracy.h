#pragma once
// The normal-accuracy experiment: how far the contact normal of each model (contact_normal.h) is
// from the exact surface normal, per sphere-tree level. This is the point of the closest feature
// map paper (Giang & O'Sullivan 2006): a contact resolved high in the tree should still get a
// polygon-level normal. Used by `clod experiment normals`, the tests and
// docs/closest-feature-maps.md. Not meant for the query path.
//
// Contact-point distribution (the same points for every model):
//   For tree level L, repeat: pick a sphere i of level L uniformly at random, a direction u
//   uniformly on the unit sphere, and let p = c_i + r_i u (a point on the sphere's surface, where
//   a sphere first touches another one). Keep p only if its exact distance to the mesh
//   (MeshDistance::closestPoint) is at most nearSurfaceFraction * r_i: the sphere's surface there
//   is near the mesh surface, i.e. a contact resolved at this sphere approximates a real contact
//   there. Stop after pointsPerLevel kept points or maxAttemptsPerLevel tries.
//   Reference normal: the exact closest-feature normal at p over the whole mesh
//   (MeshDistance::closestPoint(p).normal: face normal or angle-weighted pseudonormal).
//   Model normal: contactNormal(model, tree, maps, i, p), i.e. D&O = u, average = the sphere's
//   average normal, CFM = the stored normal of the sample nearest to u.
//   Error: the angle between model and reference normal, in degrees.
// Randomness: SplitMix64 from `seed`, one stream per (level, attempt index), so results do not
// depend on the number of threads.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "clod/closest_feature_map.h"
#include "clod/contact_normal.h"
#include "clod/sphere_tree.h"

namespace clod {

class MeshDistance;

struct NormalAccuracySettings {
  /// Contact points kept per level (>= 1).
  std::uint32_t pointsPerLevel = 2000;
  /// Tries per level before giving up on reaching pointsPerLevel (>= pointsPerLevel).
  std::uint64_t maxAttemptsPerLevel = 400000;
  /// A point p on sphere i is kept if dist(p, mesh) <= nearSurfaceFraction * r_i; in (0, 1].
  double nearSurfaceFraction = 0.25;
  std::uint64_t seed = 2006;
};

/// One model to evaluate: `model`, looking up `maps` (which must belong to the tree; for
/// kDingliana and kAverage any map of the tree serves, they read only its average normals).
struct NormalAccuracyCandidate {
  std::string label;  ///< e.g. "dos", "average", "cfm-adaptive-polar"
  ContactNormalModel model = ContactNormalModel::kClosestFeatureMap;
  const ClosestFeatureMap* maps = nullptr;
};

/// Angle error statistics in degrees. Percentiles by the nearest-rank method on the sorted errors.
struct AngleErrorStats {
  double medianDeg = 0.0;
  double p95Deg = 0.0;
  double meanDeg = 0.0;
  double maxDeg = 0.0;
};

/// Statistics of one level; `models` is parallel to the candidate list.
struct NormalAccuracyLevel {
  std::uint32_t level = 0;
  std::uint32_t spheres = 0;
  std::uint32_t points = 0;     ///< kept contact points (< pointsPerLevel if attempts ran out)
  std::uint64_t attempts = 0;   ///< points tried
  std::vector<AngleErrorStats> models;
};

/// Runs the experiment on every level of `tree`. In parallel (TBB), deterministic.
/// Cost: attempts x (one exact closest-point query) + points x candidates lookups.
/// Throws clod::Error(kInvalidArgument) if settings are out of range, a candidate has no maps
/// or maps that do not match the tree's sphere count, or the candidate list is empty.
std::vector<NormalAccuracyLevel> measureNormalAccuracy(const MeshDistance& mesh, const SphereTree& tree,
                                                       std::span<const NormalAccuracyCandidate> candidates,
                                                       const NormalAccuracySettings& settings);

/// Median / 95th percentile / mean / max of angle errors in degrees (copies and sorts).
/// All zero for an empty input.
AngleErrorStats computeAngleErrorStats(std::span<const double> errorsDeg);

}  // namespace clod
