#pragma once
// Closest feature maps (CFM): per sphere of a sphere-tree, the outward normal of the mesh feature
// nearest to each of a set of sample points on the sphere's surface, so that a contact resolved
// at any level of the tree gets a polygon-level normal by one table lookup.
//
// Paper: Giang & O'Sullivan, "Approximate collision response using closest feature maps",
// Computers & Graphics 30 (2006) 423-431, sections 4-5 (maps, sampling, retrieval, progressive
// refinement, single-normal spheres). docs/closest-feature-maps.md explains every choice made
// here and gives the measured accuracy.
//
// What is stored (and only that, as the paper suggests in section 4: "store only the normal"):
//   * one flat pool of octahedrally encoded unit normals (normal_encoding.h), 16 bits each by
//     default (error <= octahedralErrorBound(8) ~ 0.95 deg), or 32 bits (<= 0.0037 deg);
//   * per sphere: the offset of its first normal in the pool and whether it stores a single
//     normal (see "single-normal spheres" below);
//   * per tree level: the stack count of that level's sampling (progressive refinement); the
//     SphereSampling tables are built once per level and shared by every sphere of the level;
//   * per sphere, the area-weighted average normal of its responsible triangles (12 bytes), for
//     the averaging straw man of contact_normal.h.
//
// Definition of a stored normal. For sphere i with centre c, radius r and responsible triangles
// T_i (SphereTree::triangles(i)), and sample direction u_k of the level's sampling, sample point
// s = c + r u_k. The stored normal is MeshDistance::closestPointAmong(s, T_i).normal: the outward
// normal of the feature of T_i nearest to s - the face normal if the nearest point is inside a
// triangle, else the angle-weighted pseudonormal (of the whole mesh) of the nearest edge or
// vertex. Inside/outside does not matter, only the nearest feature (paper, section 4).
//
// Progressive refinement (paper section 5): level l uses
//   stacks(l) = max(minStacks, stacksAtLevel(rootStacks, l))
// i.e. the root's stack count halved per level with integer division, floored at minStacks
// (default 2: the paper's 10-stack leaves, 3 samples, instead of falling to a single sample on
// trees deeper than the paper's three levels). For geodesic and HEALPix the stack count maps to a
// resolution of similar sample count (samplingResolutionForStacks).
//
// Single-normal spheres (paper section 5, "a sphere that bounds a single polygon ... stores just
// the associated closest feature"): a sphere stores one normal exactly when every one of its
// samples would store the same normal (all within kSingleNormalAngle of the first sample's normal
// before encoding). This is checked, not assumed from the triangles: a sphere responsible only for
// coplanar triangles of a box face still gets the edge pseudonormal for samples beyond the face's
// border, so it collapses only if no sample lies beyond that border. Hence the map gives, for every
// sphere and direction, exactly what the full map would (up to kSingleNormalAngle + encoding).
//
// Thread safety: a built map is immutable; every const method may be called concurrently.
// Lookups never allocate, lock or throw.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "clod/math.h"
#include "clod/sphere_sampling.h"
#include "clod/sphere_tree.h"

namespace clod {

class MeshDistance;

/// How the normals of the pool are encoded. Values are stable (bake files store them).
enum class NormalCodec : std::uint8_t {
  kOctahedral16 = 0,  ///< 8+8 bit octahedral code; error <= octahedralErrorBound(8) ~ 0.953 deg
  kOctahedral32 = 1,  ///< 16+16 bit octahedral code; error <= octahedralErrorBound(16) ~ 0.0037 deg
};

/// "oct16" or "oct32".
std::string_view normalCodecName(NormalCodec codec) noexcept;
/// Inverse of normalCodecName; throws clod::Error(kInvalidArgument) naming the text.
NormalCodec parseNormalCodec(std::string_view name);
/// Upper bound (radians) on the angle between a normal and its decoded code.
double normalCodecErrorBound(NormalCodec codec) noexcept;

/// Two sample normals closer than this (radians) count as "the same normal" for the
/// single-normal test. Far below any encoding error, so collapsing never changes a decoded normal
/// by more than the encoding already does.
inline constexpr double kSingleNormalAngle = 1e-6;

/// How a map is built.
struct ClosestFeatureMapSettings {
  /// Sampling scheme of every sphere (sphere_sampling.h). The paper's is adaptive polar.
  SamplingScheme scheme = SamplingScheme::kAdaptivePolar;
  /// Stacks at the root, in [1, maxSamplingResolution(kPolar)] (the paper: 10 or 16, "enough").
  /// Default 16: at 10 stacks the root maps of sharp CAD parts (fandisk) are too coarse to beat
  /// D&O there; at 16 CFM beats D&O and averaging at every level of every shared closed mesh
  /// (`clod experiment normals`, docs/benchmarks/cfm.md). Pass 10 for the paper's Table 1 setup.
  int rootStacks = 16;
  /// Lower bound of the per-level stack count, in [1, rootStacks]. 1 reproduces the paper's
  /// halving down to one sample; the default 2 keeps at least the paper's leaf resolution.
  int minStacks = 2;
  /// Encoding of the stored normals.
  NormalCodec codec = NormalCodec::kOctahedral16;
};

/// Checks `settings` against the ranges documented above (a known scheme and codec, rootStacks in
/// [1, maxSamplingResolution(kPolar)], minStacks in [1, rootStacks]); throws
/// clod::Error(kInvalidArgument) naming the field. buildClosestFeatureMap and
/// ClosestFeatureMap::fromData call it.
void validateClosestFeatureMapSettings(const ClosestFeatureMapSettings& settings);

/// Plain data of a map: what a bake file stores. Sizes are consistent with a tree of
/// `sphereOffset.size()` spheres and `levelStacks.size()` levels (ClosestFeatureMap::fromData
/// checks everything).
struct ClosestFeatureMapData {
  ClosestFeatureMapSettings settings;
  /// Stack count of each tree level's sampling, root first (see the refinement rule above).
  std::vector<std::uint32_t> levelStacks;
  /// Per sphere: index of its first normal in the pool. A full sphere owns pool entries
  /// [offset, offset + samples of its level); a single-normal sphere owns [offset, offset + 1).
  /// Spheres own consecutive, non-overlapping ranges in sphere order that cover the pool.
  std::vector<std::uint32_t> sphereOffset;
  /// Per sphere: 1 if it stores a single normal, 0 otherwise.
  std::vector<std::uint8_t> sphereSingle;
  /// The pool: codes16 for kOctahedral16, codes32 for kOctahedral32 (the other one is empty).
  std::vector<std::uint16_t> codes16;
  std::vector<std::uint32_t> codes32;
  /// Per sphere, x y z of the area-weighted mean of its responsible triangles' face normals,
  /// normalised; (0, 0, 0) when the length of the area-weighted sum is at most 1e-9 times the
  /// triangles' total area (the normals cancel, e.g. a sphere bounding a closed component) or
  /// the sphere has no triangles (contact_normal.h then falls back to D&O).
  std::vector<float> averageNormals;
};

/// An immutable closest feature map for one sphere-tree (build with buildClosestFeatureMap or
/// load with fromData). Memory: ~2 (or 4) bytes per stored normal + 17 bytes per sphere + the
/// per-level sampling tables.
class ClosestFeatureMap {
public:
  /// An empty map (no spheres); only assignment and sphereCount() are meaningful.
  ClosestFeatureMap() = default;

  /// Checks `data` against `tree` and builds the lookup tables (one SphereSampling per level).
  /// Throws clod::Error(kInvalidArgument) with a message naming the field and index when:
  /// the scheme or codec is unknown, rootStacks/minStacks are out of range, levelStacks differs
  /// from the refinement rule for tree.levelCount() levels, per-sphere arrays are not
  /// tree.sphereCount() long, offsets do not tile the pool exactly, the pool of the other codec
  /// is non-empty, or an average normal is non-finite or neither ~unit nor zero.
  /// O(spheres + pool + samplings).
  static ClosestFeatureMap fromData(ClosestFeatureMapData data, const SphereTree& tree);

  /// The data this map was built from (for saving).
  const ClosestFeatureMapData& data() const noexcept { return data_; }
  const ClosestFeatureMapSettings& settings() const noexcept { return data_.settings; }

  std::uint32_t sphereCount() const noexcept { return static_cast<std::uint32_t>(data_.sphereOffset.size()); }
  std::uint32_t levelCount() const noexcept { return static_cast<std::uint32_t>(data_.levelStacks.size()); }

  /// The contact normal the map gives for a contact on sphere `sphere` seen from its centre in
  /// direction `directionFromCentre` (mesh coordinates; need not be unit length): the decoded
  /// stored normal of the sample nearest to that direction (exact nearest: SphereSampling::
  /// nearest), or the sphere's single normal. A zero or non-finite direction gives the normal of
  /// sample 0. Unit length. CLOD_ASSERT(sphere < sphereCount()). O(1), no allocation.
  Vec3 normal(std::uint32_t sphere, const Vec3& directionFromCentre) const noexcept;

  /// Index, within the sphere's sampling, of the sample the lookup uses for this direction
  /// (0 for single-normal spheres). Same contract as normal().
  std::uint32_t sampleIndex(std::uint32_t sphere, const Vec3& directionFromCentre) const noexcept;

  /// Decoded stored normal `sample` of `sphere` (CLOD_ASSERT sample < storedNormalCount(sphere)).
  Vec3 storedNormal(std::uint32_t sphere, std::uint32_t sample) const noexcept;

  /// True if the sphere stores one normal for all directions.
  bool isSingleNormal(std::uint32_t sphere) const noexcept { return data_.sphereSingle[sphere] != 0; }
  /// Normals the sphere stores: 1 if single-normal, else samplesAtLevel of its level.
  std::uint32_t storedNormalCount(std::uint32_t sphere) const noexcept;

  /// Level of a sphere (from the tree's level offsets, kept by the map).
  std::uint32_t sphereLevel(std::uint32_t sphere) const noexcept { return sphereLevel_[sphere]; }
  /// Stack count and sampling of a level (CLOD_ASSERT level < levelCount()).
  int stacksAtTreeLevel(std::uint32_t level) const noexcept { return static_cast<int>(data_.levelStacks[level]); }
  const SphereSampling& levelSampling(std::uint32_t level) const noexcept { return samplings_[level]; }
  /// Sample points of each sphere of `level` (the level's sampling size): the paper's
  /// "samples per sphere" of Table 1.
  std::uint32_t samplesAtLevel(std::uint32_t level) const noexcept { return samplings_[level].size(); }

  /// Area-weighted average normal of the sphere's responsible triangles, or (0,0,0) when it is
  /// undefined (see ClosestFeatureMapData::averageNormals).
  Vec3 averageNormal(std::uint32_t sphere) const noexcept;

  /// Normals in the pool and bytes they take (2 or 4 each).
  std::size_t poolSize() const noexcept;
  std::size_t poolBytes() const noexcept;

private:
  ClosestFeatureMapData data_;
  std::vector<SphereSampling> samplings_;    // one per tree level
  std::vector<std::uint32_t> sphereLevel_;   // per sphere
};

/// The stack count of tree level `level`: max(minStacks, stacksAtLevel(rootStacks, level)).
/// CLOD_ASSERT: 1 <= minStacks <= rootStacks, level >= 0.
int closestFeatureMapStacks(const ClosestFeatureMapSettings& settings, int level) noexcept;

/// Builds the map of `tree` over `mesh` (the tree must have been built for this mesh). In
/// parallel over spheres (TBB); deterministic. Cost: sum over spheres of
/// (samples of its level) x (its responsible triangles) point-triangle distances, e.g. ~0.1 s
/// for spot (5,856 triangles, 8-ary, 5 levels, 10 stacks) on 2 cores (docs/benchmarks/cfm.md).
/// Throws clod::Error(kInvalidArgument) for settings out of range (message names the setting)
/// or a tree that does not fit the mesh (a triangle index out of range, a sphere without
/// triangles, inconsistent arrays).
ClosestFeatureMap buildClosestFeatureMap(const MeshDistance& mesh, const SphereTree& tree,
                                         const ClosestFeatureMapSettings& settings);

}  // namespace clod
