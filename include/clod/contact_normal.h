#pragma once
// Contact normal models for a contact on one sphere of a sphere-tree: the per-sphere half of
// what the narrow phase needs when a query stops at some level of the tree (combining the two
// spheres of a pair is the narrow phase's job).
//
// The three models (Giang & O'Sullivan 2006, sections 2, 4 and 6):
//   * kDingliana ("dos"): Dingliana & O'Sullivan's approximation - the direction from the
//     sphere's centre to the contact point. Cheap; reflects the sphere, not the surface.
//   * kAverage ("average"): the straw man the paper argues against - the area-weighted average of
//     the face normals of the triangles the sphere is responsible for, whatever the contact point.
//     At a box corner it is the diagonal, which causes unwanted rotation.
//   * kClosestFeatureMap ("cfm"): the closest feature map's stored normal for the direction from
//     the centre to the contact point (ClosestFeatureMap::normal).
//
// All normals are unit vectors in mesh (local) coordinates and point out of the mesh (for D&O: out
// of the sphere).

#include <cstdint>
#include <span>
#include <string_view>

#include "clod/closest_feature_map.h"
#include "clod/math.h"
#include "clod/sphere_tree.h"

namespace clod {

/// Values are stable (tools and files use them).
enum class ContactNormalModel : std::uint8_t {
  kDingliana = 0,         ///< "dos": centre-to-point direction
  kAverage = 1,           ///< "average": area-weighted mean of the sphere's triangle normals
  kClosestFeatureMap = 2, ///< "cfm": closest feature map lookup
};

/// All models, in enum order.
std::span<const ContactNormalModel> allContactNormalModels() noexcept;
/// "dos", "average", "cfm".
std::string_view contactNormalModelName(ContactNormalModel model) noexcept;
/// Inverse of contactNormalModelName (exact, case-sensitive); throws clod::Error(kInvalidArgument)
/// naming the text and listing the valid names.
ContactNormalModel parseContactNormalModel(std::string_view name);

/// The outward contact normal `model` gives for a contact at `pointLocal` (mesh coordinates) on
/// sphere `sphere` of `tree`; `maps` must have been built for `tree` (kAverage and
/// kClosestFeatureMap read it; kDingliana does not).
/// Degenerate cases, so the result is always a unit vector:
///   kDingliana: pointLocal at the centre (closer than 1e-300) -> the sphere's average normal,
///     or +z if that is undefined too;
///   kAverage: undefined average (normals cancel) -> kDingliana;
///   kClosestFeatureMap: pointLocal at the centre -> the normal of sample 0.
/// CLOD_ASSERT: sphere < tree.sphereCount() == maps.sphereCount(). O(1), no allocation.
Vec3 contactNormal(ContactNormalModel model, const SphereTree& tree, const ClosestFeatureMap& maps,
                   std::uint32_t sphere, const Vec3& pointLocal) noexcept;

}  // namespace clod
