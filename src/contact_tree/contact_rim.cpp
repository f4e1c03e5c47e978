// Contact-tree manifolds pushed out to the rim of their contact area (contact_rim.h).
#include "clod/contact_rim.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace clod {
namespace {

struct FieldPair {
  const ContactTree& a;
  const Pose& xfA;
  const ContactTree& b;
  const Pose& xfB;

  // Signed distances of world point p to A and to B, with their error bounds.
  void at(const Vec3& p, ContactFieldSample& fa, ContactFieldSample& fb) const {
    fa = a.sample(xfA.applyInverse(p));
    fb = b.sample(xfB.applyInverse(p));
  }
};

// The walk's test: both fields within half their tree's interpolation error eps_s (and a
// rounding slack) of their values at the contact. The point stays on the one face, at the same
// depth under the other, so the contact's depth still holds there; past a face's edge a field
// rises about as fast as the walk goes, so the walk ends within eps_s of the rim.
constexpr double kWalkTolerance = 0.5;

struct Walk {
  const FieldPair& fields;
  ContactFieldSample startA, startB;
  double slack;
  double backOff;  // the most a field may have risen undetected past a rim: its tolerance

  bool holds(const ContactFieldSample& fa, const ContactFieldSample& fb) const {
    return std::abs(fa.distance - startA.distance) <= kWalkTolerance * fields.a.errorAbs + slack &&
           std::abs(fb.distance - startB.distance) <= kWalkTolerance * fields.b.errorAbs + slack;
  }
  double drift(const ContactFieldSample& fa, const ContactFieldSample& fb) const {
    return std::abs(fa.distance - startA.distance) + std::abs(fb.distance - startB.distance);
  }
};

// Where a walk from `from` along unit `direction` ended: how far it got, the fields' change there,
// and (when it met a rim) the world gradient of the field that rose past its tolerance at the
// first probe that failed -- the rim's outward normal.
struct WalkEnd {
  double reached = 0.0;
  double drift = 0.0;
  bool metRim = false;
  Vec3 rimNormal = Vec3::Zero();
};

// Marches in equal steps to the first probe that fails, then halves the last step. Past a rim a
// field rises about as fast as the walk goes, so a probe that held may lie as far beyond it as
// the fields changed there (and up to the tolerance more), where the normal line through the point
// misses a body: the end steps back by both.
WalkEnd walkAlong(const Walk& walk, const Vec3& from, const Vec3& direction, double step,
                  const ContactRimSettings& settings, std::uint32_t& queries) {
  WalkEnd end;
  ContactFieldSample fa, fb;
  double bad = -1.0;
  auto probe = [&](double t) {
    walk.fields.at(from + t * direction, fa, fb);
    ++queries;
    if (walk.holds(fa, fb)) {
      end.reached = t;
      end.drift = walk.drift(fa, fb);
      return true;
    }
    bad = t;
    if (!end.metRim) {  // the first probe that failed names the rim
      end.metRim = true;
      const bool aRose = std::abs(fa.distance - walk.startA.distance) > kWalkTolerance * walk.fields.a.errorAbs;
      end.rimNormal = aRose ? Vec3(walk.fields.xfA.rotation * fa.gradient) : Vec3(walk.fields.xfB.rotation * fb.gradient);
    }
    return false;
  };
  for (std::uint32_t k = 1; k <= settings.steps && probe(k * step); ++k) {
  }
  if (!end.metRim) return end;
  for (std::uint32_t h = 0; h < settings.halvings; ++h) probe(0.5 * (end.reached + bad));
  end.reached = std::max(0.0, end.reached - end.drift - walk.backOff);
  return end;
}

// The contacts that walk: touching, with normals within 2 degrees of the deepest one's -- one
// face-on-face patch, provided their points lie on two parallel planes across that normal (the
// samples lie on either face: within the deepest depth and both trees' eps_s). Only such a patch
// has a support polygon whose rim the walk can find; on a tilted, curved or edge contact the normal line through a point moved at
// equal field values can pass beside a body (measured: the contact tree's error-bound rate on two
// boxes in random overlapping poses fell from 75 % to 43 % when every manifold walked). Contacts
// of the patch whose normals the field tilts (at a flush edge) stay where they are.
constexpr double kSameNormalCos = 0.99939;  // 2 degrees

bool walks(const Contact& c, const Vec3& patchNormal, double marginAbs) {
  return c.depth >= -marginAbs && c.normal.dot(patchNormal) >= kSameNormalCos;
}

bool faceOnFace(std::span<const Contact> contacts, const Vec3& patchNormal, double marginAbs, double epsAbs) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, deep = -lo;
  int count = 0;
  for (const Contact& c : contacts) {
    if (!walks(c, patchNormal, marginAbs)) continue;
    const double h = patchNormal.dot(c.point);
    lo = std::min(lo, h), hi = std::max(hi, h);
    deep = std::max(deep, c.depth);
    ++count;
  }
  return count >= 2 && hi - lo <= std::max(deep, 0.0) + 2.0 * epsAbs;
}

}  // namespace

std::uint32_t extendContactsToRim(const ContactTree& a, const Pose& xfWorldFromA, const ContactTree& b,
                                  const Pose& xfWorldFromB, std::span<Contact> contacts, double marginAbs,
                                  const ContactRimSettings& settings) {
  // The patch: the deepest touching contact's normal; its centroid and radius over all touching
  // contacts (the shape of the contact area).
  const Contact* deepest = nullptr;
  Vec3 centroid = Vec3::Zero();
  std::uint32_t touching = 0;
  for (const Contact& c : contacts) {
    if (c.depth < -marginAbs) continue;
    if (!deepest || c.depth > deepest->depth) deepest = &c;
    centroid += c.point;
    ++touching;
  }
  if (touching < 2 || settings.steps == 0) return 0;
  const Vec3 patchNormal = deepest->normal;
  centroid /= double(touching);
  double radius = 0.0;
  for (const Contact& c : contacts) {
    if (c.depth < -marginAbs) continue;
    const Vec3 r = c.point - centroid;
    radius = std::max(radius, (r - r.dot(patchNormal) * patchNormal).norm());
  }
  const double slack = 1e-9 * (a.meshDiagonal + b.meshDiagonal);
  if (!(radius > 1e3 * slack) || !faceOnFace(contacts, patchNormal, marginAbs, std::max(a.errorAbs, b.errorAbs))) return 0;
  const FieldPair fields{a, xfWorldFromA, b, xfWorldFromB};
  const double step = settings.reachRel * radius / double(settings.steps);
  std::uint32_t queries = 0;
  for (Contact& c : contacts) {
    if (!walks(c, patchNormal, marginAbs)) continue;
    Vec3 out = c.point - centroid;
    out -= out.dot(c.normal) * c.normal;
    const double length = out.norm();
    if (!(length > 1e-3 * radius)) continue;  // the centroid itself: no outward direction
    out /= length;
    Walk walk{fields, {}, {}, slack, kWalkTolerance * std::max(a.errorAbs, b.errorAbs)};
    fields.at(c.point, walk.startA, walk.startB);
    ++queries;
    // Out from the centroid to the rim, then along the rim (perpendicular to the outward normal
    // of the rim it met, away from the centroid) to a corner.
    const WalkEnd outward = walkAlong(walk, c.point, out, step, settings, queries);
    Vec3 at = c.point + outward.reached * out;
    double drift = outward.drift;
    if (outward.metRim) {
      Vec3 along = c.normal.cross(outward.rimNormal);
      if (along.dot(at - centroid) < 0.0) along = -along;
      if (along.norm() > 1e-6 && std::abs(along.normalized().dot(at - centroid)) > 1e-3 * radius) {
        along.normalize();
        const WalkEnd sideways = walkAlong(walk, at, along, step, settings, queries);
        at += sideways.reached * along;
        drift = std::max(drift, sideways.drift);
      }
    }
    if (at != c.point) {
      c.point = at;
      c.errorBound += drift;  // the depth holds there within the fields' change
    }
  }
  return queries;
}

}  // namespace clod
