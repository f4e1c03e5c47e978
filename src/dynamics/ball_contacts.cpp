#include "dynamics/ball_contacts.h"

#include <algorithm>
#include <cmath>

namespace clod::detail {
namespace {

// Normals closer than ~3 deg touch the ball at points less than 5 % of its radius apart: one
// contact. (A ball on a flat face gets the face's one normal from every corner of its facet; on a
// curved surface the other body's samples differ by their own facets' angles.)
constexpr double kSameNormalCos = 0.9986;

}  // namespace

void ballBallAnswer(const Vec3& centreA, double radiusA, const Vec3& centreB, double radiusB, QueryResult& result) {
  const Vec3 d = centreA - centreB;
  const double distance = d.norm();
  const double gap = distance - radiusA - radiusB;
  result.contacts.clear();
  result.frontier.clear();
  result.intersectingTriangles.clear();
  result.tests = result.sphereTests = 1;
  result.triangleTests = 0;
  result.finished = true;
  result.stop = QueryStop::kFinished;
  result.minLevel = result.maxLevel = 0;
  result.pairsAnswered = 0;
  result.fallbackPairs = 0;
  result.fallbackModel = ContactModel::kExact;
  result.separation = std::max(gap, 0.0);
  result.seconds = 0.0;
  result.colliding = gap <= 0.0;
  result.rawContacts = result.colliding ? 1 : 0;
  if (!result.colliding) return;
  Contact c;
  c.normal = distance > 0.0 ? Vec3(d / distance) : Vec3::UnitZ();
  c.depth = -gap;
  // Midway between A's deepest point (its surface toward B) and B's (its surface toward A).
  c.point = 0.5 * ((centreA - radiusA * c.normal) + (centreB + radiusB * c.normal));
  c.errorBound = 0.0;
  c.featureA = c.featureB = 0;  // the root spheres: the balls themselves
  c.featureKind = ContactFeature::kSphere;
  result.contacts.push_back(c);
}

std::uint32_t putContactsOnBall(std::vector<Contact>& contacts, const Vec3& centre, double radius, bool ballIsA,
                                const CollisionBody& other, const Pose& otherPose, ContainmentScratch& scratch) {
  std::uint32_t queries = 0;
  for (Contact& c : contacts) {
    Vec3 surface = ballIsA ? contactPointOnB(c) : contactPointOnA(c);
    // `outward`: the other body's outward normal, from it toward the ball.
    Vec3 outward = ballIsA ? c.normal : Vec3(-c.normal);
    FieldValue f;
    ++queries;
    const double reach = std::abs(c.depth) + c.errorBound + 1e-9 * radius;
    if (exactBodyFieldWithin(other, otherPose.applyInverse(surface), reach, scratch, f)) {
      outward = otherPose.rotation * f.gradient;
      surface -= f.distance * outward;  // onto the surface
      c.errorBound = f.errorBound;        // the ball's side is exact, and so is the field
    }
    // A seed whose surface turns its back on the ball's centre (the centre lies behind it) is no
    // point the ball touches: a coarse contact of a ball rolling down a slab at 16 tests per frame
    // (the average model) had its seed deep in the slab, nearer its underside, and the ball was
    // pushed down through it. Then the other body's surface point nearest the centre answers.
    if (outward.dot(centre - surface) < 0.0) {
      ++queries;
      if (exactBodyFieldWithin(other, otherPose.applyInverse(centre), radius + reach, scratch, f)) {
        outward = otherPose.rotation * f.gradient;
        surface = centre - f.distance * outward;
        c.errorBound = f.errorBound;
      }
    }
    c.normal = ballIsA ? outward : Vec3(-outward);
    const double reachFromCentre = outward.dot(centre - surface);  // the centre's height over it
    c.depth = radius - reachFromCentre;
    c.point = centre - (radius - 0.5 * c.depth) * outward;
  }
  // Deepest first, then each contact joins the first kept one whose normal it shares.
  std::sort(contacts.begin(), contacts.end(), [](const Contact& l, const Contact& r) { return l.depth > r.depth; });
  std::size_t kept = 0;
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    bool same = false;
    for (std::size_t k = 0; k < kept && !same; ++k) same = contacts[k].normal.dot(contacts[i].normal) > kSameNormalCos;
    if (!same) contacts[kept++] = contacts[i];
  }
  contacts.resize(kept);
  return queries;
}

}  // namespace clod::detail
