#pragma once
// Contacts of ball bodies (RigidBodyDesc::ballRadius; docs/dynamics.md, "Balls"). A ball's mesh
// is a polyhedron around it; the narrow phase answers for the polyhedron, and these put the
// ball's side of the answer on the ball.

#include <cstdint>
#include <vector>

#include "clod/collision_body.h"
#include "clod/contact.h"
#include "clod/math.h"
#include "clod/query.h"
#include "narrowphase/containment.h"

namespace clod::detail {

/// Two balls A and B (centres, radii) as a finished query's answer: one test; where they touch,
/// the one contact along the centre line, normal from B's centre toward A's (+z where the
/// centres coincide), point midway through the overlap, error bound 0; where they do not, no
/// contact and `separation` the gap between the surfaces.
void ballBallAnswer(const Vec3& centreA, double radiusA, const Vec3& centreB, double radiusB, QueryResult& result);

/// Puts the ball's side of a query's contacts on the ball. Each contact's point on the other body
/// (contactPointOnA/B) is a seed: the other body's exact field there (exactBodyFieldWithin, within
/// the contact's depth and error bound) gives its surface point and outward normal; the contact
/// takes that normal and the depth that leaves the ball: its radius minus the surface point's
/// distance from the centre along the normal (negative where the polyhedron overlaps but the ball
/// does not: a speculative contact). A seed with no surface that near keeps the model's normal;
/// a seed whose surface the ball's centre lies behind takes the surface point nearest the centre.
/// Contacts whose normals then differ by less than ~3 deg are one contact, the deepest: a ball
/// touches a face at one point, and the polyhedron's corners on it would be copies of it.
/// `ballIsA` says which side of the contacts (Contact's convention) the ball is; `other` and
/// `otherPose` are the other body. Returns the field queries made (the caller counts them as
/// tests).
std::uint32_t putContactsOnBall(std::vector<Contact>& contacts, const Vec3& centre, double radius, bool ballIsA,
                                const CollisionBody& other, const Pose& otherPose, ContainmentScratch& scratch);

}  // namespace clod::detail
