#pragma once
// Containment: one closed body wholly inside another. Their surfaces do not meet, so the
// sphere-tree and contact-tree descents find no overlapping surface pair and every model would
// answer "apart" -- for the deepest penetration there is. queryContacts calls this when a query
// ends without a contact although the two root spheres overlap (docs/narrow-phase.md,
// "Containment"). Internal to the narrow phase.
#include <cstdint>
#include <utility>
#include <vector>

#include "clod/collision_body.h"
#include "clod/contact.h"
#include "clod/math.h"

namespace clod::detail {

/// Working memory of containmentContacts (reused: no allocation once grown).
struct ContainmentScratch {
  struct BoxEntry {
    double lowerBound;    // squared distance to the slot's box
    std::uint32_t child;  // node index (count 0), or first position in the BVH's order
    std::uint32_t count;  // triangles of a leaf slot
  };
  std::vector<BoxEntry> stack;           // best-first triangle-BVH search
  std::vector<std::uint32_t> triangles;  // triangles around a closest vertex/edge
};

/// Signed distance of a body's surface at p (body frame), negative inside, with the field's
/// gradient direction (unit; points toward increasing distance, i.e. out of the body at its
/// nearest surface) and an error bound on the distance (0: exact). A best-first search of the
/// body's triangle BVH with closestPointOnTriangle (proximity.h), signed by the angle-weighted
/// pseudonormal of the closest feature (Baerentzen & Aanaes 2005; exact for closed, consistently
/// oriented meshes). O(log T) typical, no allocation once the scratch has grown. The contact tree
/// is not used: deep inside a body its coarse cells' gradient is far off (a sphere 0.7 inside a
/// box's +x face: 33 deg).
struct FieldValue {
  double distance = 0.0;
  Vec3 gradient = Vec3::UnitX();
  double errorBound = 0.0;
};
FieldValue exactBodyField(const CollisionBody& body, const Vec3& pLocal, ContainmentScratch& scratch);

/// Triangles of the body that a point on them does not press through: `isFlush(context, t)` is
/// asked only for a triangle whose plane p lies on (within `onSurface`; a flat face is often
/// several triangles, and the field of the one beside p would stand in for the face). A corner of a box standing flush
/// with a side face of the body (a box on an L-shaped body's floor, as wide as it) lies on that
/// face, where the body's field is 0 -- so the corner, 1 cm below the floor's top, was not inside
/// -- yet the box's material lies behind that face as the body's does: the face is not a contact
/// surface there, and the field past it (the floor's top) is the corner's.
struct FlushFaces {
  double onSurface = 0.0;
  const void* context = nullptr;
  bool (*isFlush)(const void* context, std::uint32_t triangle) = nullptr;
};

/// exactBodyField where the surface lies within maxDistance of p, searching only that far (the
/// cost of a point far from the surface is then a few box tests); false, `f` untouched, where
/// it does not. With `flush`, the triangles it names under p are not the surface (FlushFaces).
bool exactBodyFieldWithin(const CollisionBody& body, const Vec3& pLocal, double maxDistance, ContainmentScratch& scratch,
                          FieldValue& f, const FlushFaces* flush = nullptr);


/// Containment contacts (A's frame, normal from B toward A) when A lies wholly inside B or B
/// inside A. Two triggers:
///  * haveContacts false (the query found none) and the root spheres overlap: a seed vertex of
///    each body is tested against the other body's field; inside a closed body means wholly
///    inside (the surfaces do not meet, or the query would have found a contact);
///  * haveContacts true: the model's contacts stand unless a body's root sphere lies wholly
///    inside the other closed body (the field at its centre < -its radius): then the surfaces
///    cannot meet, and the model's contacts came from loose sphere pairs (the caller replaces
///    them). Tested only when that root sphere lies inside the other's root sphere.
/// Contacts: up to min(maxContacts, 8) well-spread vertices of the inner body, all with the
/// outer field's gradient at the inner body's root-sphere centre (or at the seed, if the centre
/// is outside) as normal, each with its own depth -signed distance and error bound 0. Appends to
/// `out` and sets `found`; returns the number of field queries made (at most 2 + 1 + 8), which
/// the caller counts as tests.
std::uint32_t containmentContacts(const CollisionBody& a, const CollisionBody& b, const Pose& xfAFromB,
                                  std::uint32_t maxContacts, bool haveContacts, ContainmentScratch& scratch,
                                  std::vector<Contact>& out, bool& found);

}  // namespace clod::detail
