#pragma once
// Contacts between two rigid bodies A and B, as the narrow phase (query.h) returns them and the
// dynamics consumes them, and the reduction of many raw contacts to a small manifold.
//
// Conventions (docs/conventions.md, the same everywhere in clod):
//   * everything is in the world frame;
//   * the contact normal is a unit vector pointing FROM BODY B TOWARD BODY A: pushing A along
//     +normal (or B along -normal) separates them;
//   * depth is positive when the bodies penetrate, in the bodies' length unit.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "clod/math.h"

namespace clod {

/// How a query turns what its traversal reached into contacts (docs/narrow-phase.md).
/// Values are stable: tools and files use them.
enum class ContactModel : std::uint8_t {
  /// Dingliana & O'Sullivan: for each overlapping sphere pair of the frontier, the point on the
  /// centre line where the plane of the spheres' intersection circle cuts it, the normal along
  /// the centre line (B's centre toward A's), depth r_A + r_B - |c_A - c_B|.
  kDos = 0,
  /// The straw man of Giang & O'Sullivan: D&O point and depth, normal from the area-weighted
  /// average normals of the triangles each sphere bounds (ClosestFeatureMap::averageNormal),
  /// combined as normalize(n_B - n_A) (falls back to D&O where that is undefined).
  kAverage = 1,
  /// Closest feature maps: each sphere's CFM normal for the direction of the contact point from
  /// its centre, combined by the rules of docs/narrow-phase.md (a separating-axis choice where a
  /// sphere is a faceted patch); D&O point and depth, or, where a sphere is a faceted patch, the
  /// patches' overlap along the normal as depth and a point in it. Pairs whose patches a
  /// separating axis proves apart give no contact.
  kCfm = 2,
  /// Contact trees (Kaufman et al. 2007): traversal of the two contact trees, then contact
  /// sampling of the frontier cell pairs (contact_sampling.h), both ways round.
  kContactTree = 3,
  /// Polygon-level reference: triangle-triangle intersection of the leaves' triangles; one
  /// normal and depth per connected contact patch, per point in a curved patch (query.h).
  kExact = 4,
};

/// All models, in enum order.
std::span<const ContactModel> allContactModels() noexcept;
/// "dos", "average", "cfm", "contact-tree", "exact".
std::string_view contactModelName(ContactModel model) noexcept;
/// Inverse of contactModelName (exact, case-sensitive). Throws clod::Error(kInvalidArgument)
/// naming the text and listing the valid names.
ContactModel parseContactModel(std::string_view name);

/// Contact::featureA / featureB when the model does not say which feature a contact came from.
inline constexpr std::uint32_t kNoContactFeature = 0xffffffffu;

/// What Contact::featureA / featureB index (docs/narrow-phase.md, "Feature ids").
enum class ContactFeature : std::uint8_t {
  /// Not reported: featureA = featureB = kNoContactFeature (containment contacts, contacts built
  /// by hand).
  kNone = 0,
  /// Triangle indices into the two bodies' meshes (CollisionBody::mesh()): the exact model's
  /// contacts. A point on the intersection curve lies on both triangles; a vertex inside the
  /// other body (flat patches, convex polyhedra) has contactPointOnA on featureA and
  /// contactPointOnB on featureB.
  kTriangle = 1,
  /// Sphere indices into the two bodies' sphere-trees: dos, average and cfm, the exact model's
  /// cfm fallback of an interrupted query and its separating-axis answer between two convex
  /// polyhedra (the root spheres, 0 and 0: the whole bodies). The contact came from that sphere
  /// pair: its point lies within both spheres grown by the contact's depth and error bound --
  /// except cfm's exact face corners between convex polyhedra (error bound 0), which lie on the
  /// bodies' faces the two patches face along, and those may reach beyond the spheres.
  kSphere = 2,
  /// Node indices into the two bodies' contact trees (ContactCell::node): the cell pair the
  /// contact was sampled from. The sample may have slid along the surface out of its cell
  /// (contact_sampling.h), so the cells say where it started, not where it ended.
  kCell = 3,
};

/// One contact point between A and B (world frame).
struct Contact {
  Vec3 point = Vec3::Zero();    ///< the contact point
  Vec3 normal = Vec3::UnitZ();  ///< unit, from B toward A
  double depth = 0.0;           ///< penetration, > 0 when penetrating
  /// How far the depth may be off, in length units (>= 0). The promise, for a penetrating
  /// contact (depth > 0): the penetration along the normal line through `point` -- how far the
  /// point moves along -normal before it leaves A, plus how far along +normal before it leaves
  /// B -- lies within depth +- errorBound. Values: for sphere models the sum of the two
  /// spheres' radii (the surfaces are somewhere inside both spheres; it shrinks by the
  /// branching factor per level), 0 where both sides are faceted patches of convex polyhedra
  /// (clipped faces) or a vertex's exact depth below a convex body's face; for the contact tree
  /// the field's error bound; 0 for exact contacts. Measured rates and where the promise does
  /// not hold yet (exact's points on curved patches carry the patch's depth, not their own):
  /// docs/narrow-phase.md, "Error bounds". No angle is promised for the normal.
  double errorBound = 0.0;
  /// Level of the pair the contact came from: for sphere-trees max(level of A's sphere, level
  /// of B's sphere), 0 = the roots; for contact trees the deeper cell's depth.
  std::uint32_t level = 0;
  /// The features of A and B the contact came from, for matching contacts across frames (what
  /// Box2D's contact ids and Bullet's part/index pairs are for); `featureKind` says what they
  /// index: triangles of the meshes for the exact model's triangle contacts, spheres of the
  /// sphere-trees for the sphere models, nodes of the contact trees for the contact tree
  /// (ContactFeature). kNoContactFeature with ContactFeature::kNone where the narrow phase does
  /// not know them. World::separation names the closest triangles of two bodies apart.
  std::uint32_t featureA = kNoContactFeature;
  std::uint32_t featureB = kNoContactFeature;
  ContactFeature featureKind = ContactFeature::kNone;
};

/// The contact's two points, one on each body (world frame): point -/+ depth / 2 along the
/// normal, so (pointOnA - pointOnB) . normal = -depth. These are the points the world anchors in
/// the bodies and holds apart (StepReport::contactPoints, world.h). Where the model's point is
/// the middle of the penetration -- dos, average and cfm (D&O points, face-clipped corners), and
/// the exact model's face corners between convex polyhedra -- they are the two surfaces' points
/// (tested on a box in a box), and the exact model's vertices inside the other body. Its points
/// on the surfaces' intersection carry their patch's depth, and the contact tree's samples lie
/// on one of the two surfaces: there the pair is the same penetration centred on the reported
/// point, up to depth / 2 away from the surface points (docs/narrow-phase.md, "Feature ids and
/// both points").
inline Vec3 contactPointOnA(const Contact& c) { return c.point - 0.5 * c.depth * c.normal; }
inline Vec3 contactPointOnB(const Contact& c) { return c.point + 0.5 * c.depth * c.normal; }

/// How reduceManifold picks contacts.
struct ManifoldSettings {
  /// At most this many contacts are kept, >= 1.
  std::uint32_t maxContacts = 8;
  /// Contacts closer than this (length units, >= 0) to an already kept one are merged into it
  /// (dropped), so a face-on-face contact does not return many copies of one corner.
  double mergeDistanceAbs = 0.0;
  /// Normal pooling (off when > 1): every contact not kept is assigned to the nearest kept one
  /// (distance in the contact plane, as for the selection) whose normal is within this cosine of
  /// its own, and each kept contact's normal becomes the depth-weighted mean of its own and its
  /// assigned contacts' normals (weights max(depth, 0); equal weights where all are 0). A kept
  /// contact then pushes along the total penalty force of the contacts it stands for, not along
  /// its own noisy normal. Contacts whose normals differ by more (a wall next to a floor) are not
  /// pooled together. The cfm model (and an interrupted exact query) uses cos 60 deg
  /// (query.cpp, docs/narrow-phase.md).
  double poolNormalsCos = 2.0;
};

/// Reduces `contacts` to a manifold of at most settings.maxContacts well-spread contacts, in
/// place: on return the kept contacts are contacts[0 .. n), where n is the return value.
/// Rule: keep the deepest contact first (among contacts equally deep within 1e-6 of its depth or
/// 1e-4 of the contacts' extent, the one farthest from the contacts' centroid in the contact
/// plane: an end of an edge lying flat, not whichever came first), then the one farthest from
/// it, then the two farthest from the line through those (one on each side), all distances
/// measured in the plane perpendicular to the deepest contact's normal -- for a face-on-face
/// overlap, four corners; then repeatedly add the contact that adds most support: once the kept
/// contacts facing the deepest one's way (within 1 deg) span a polygon, the one farthest outside
/// it, or among those inside it but deeper than the plane of the kept depths (by 1e-4 of its
/// extent), the one farthest from the kept ones; contacts inside it and no deeper are not kept (a
/// face on a face keeps its overlap's corners only). Where no polygon has a say, farthest-point
/// sampling in the contact plane. Stop at maxContacts. A contact within
/// mergeDistanceAbs of a kept one is never kept. Other ties are broken by input order, so
/// the result depends only on the input sequence. Then, if poolNormalsCos <= 1, the kept
/// contacts' normals are pooled (ManifoldSettings::poolNormalsCos). `scratch` is reused (no allocation once it
/// has grown to contacts.size()). O(n * maxContacts). Throws clod::Error(kInvalidArgument) if
/// maxContacts == 0 or mergeDistanceAbs is negative or not finite.
std::size_t reduceManifold(std::span<Contact> contacts, const ManifoldSettings& settings,
                           std::vector<double>& scratch);

}  // namespace clod
