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

  bool holds(const ContactFieldSample& fa, const ContactFieldSample& fb) const {
    return std::abs(fa.distance - startA.distance) <= kWalkTolerance * fields.a.errorAbs + slack &&
           std::abs(fb.distance - startB.distance) <= kWalkTolerance * fields.b.errorAbs + slack;
  }
};

// Whether the touching contacts form one face-on-face patch: normals within 2 degrees of the
// first one's, points in one plane across it (within their spread of depths and both trees'
// eps_s). Only such a patch has a support polygon whose rim the walk can find; on a tilted,
// curved or edge contact the normal line through a point moved at equal field values can pass
// beside a body (measured: the contact tree's error-bound rate on two boxes in random overlapping
// poses fell from 75 % to 43 % when every manifold walked).
bool faceOnFace(std::span<const Contact> contacts, double marginAbs, double epsAbs) {
  constexpr double kSameNormalCos = 0.99939;  // 2 degrees
  const Contact* first = nullptr;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, shallow = lo, deep = -lo;
  for (const Contact& c : contacts) {
    if (c.depth < -marginAbs) continue;
    if (!first) first = &c;
    if (c.normal.dot(first->normal) < kSameNormalCos) return false;
    const double h = first->normal.dot(c.point);
    lo = std::min(lo, h), hi = std::max(hi, h);
    shallow = std::min(shallow, c.depth), deep = std::max(deep, c.depth);
  }
  return first != nullptr && hi - lo <= (deep - shallow) + 2.0 * epsAbs;
}

}  // namespace

std::uint32_t extendContactsToRim(const ContactTree& a, const Pose& xfWorldFromA, const ContactTree& b,
                                  const Pose& xfWorldFromB, std::span<Contact> contacts, double marginAbs,
                                  const ContactRimSettings& settings) {
  Vec3 centroid = Vec3::Zero();
  std::uint32_t touching = 0;
  for (const Contact& c : contacts) {
    if (c.depth < -marginAbs) continue;
    centroid += c.point;
    ++touching;
  }
  if (touching < 2 || settings.steps == 0) return 0;
  centroid /= double(touching);
  double radius = 0.0;
  for (const Contact& c : contacts) {
    if (c.depth < -marginAbs) continue;
    const Vec3 r = c.point - centroid;
    radius = std::max(radius, (r - r.dot(c.normal) * c.normal).norm());
  }
  const double slack = 1e-9 * (a.meshDiagonal + b.meshDiagonal);
  if (!(radius > 1e3 * slack) || !faceOnFace(contacts, marginAbs, std::max(a.errorAbs, b.errorAbs))) return 0;
  const FieldPair fields{a, xfWorldFromA, b, xfWorldFromB};
  const double step = settings.reachRel * radius / double(settings.steps);
  std::uint32_t queries = 0;
  for (Contact& c : contacts) {
    if (c.depth < -marginAbs) continue;
    Vec3 out = c.point - centroid;
    out -= out.dot(c.normal) * c.normal;
    const double length = out.norm();
    if (!(length > 1e-3 * radius)) continue;  // the centroid itself: no outward direction
    out /= length;
    Walk walk{fields, {}, {}, slack};
    fields.at(c.point, walk.startA, walk.startB);
    ++queries;
    const ContactFieldSample& startA = walk.startA;
    const ContactFieldSample& startB = walk.startB;
    ContactFieldSample fa, fb;
    // March out in equal steps to the first probe that fails, then halve the last step.
    double good = 0.0, bad = -1.0, drift = 0.0;
    auto driftAt = [&] { return std::abs(fa.distance - startA.distance) + std::abs(fb.distance - startB.distance); };
    for (std::uint32_t k = 1; k <= settings.steps; ++k) {
      const double t = k * step;
      fields.at(c.point + t * out, fa, fb);
      ++queries;
      if (!walk.holds(fa, fb)) {
        bad = t;
        break;
      }
      good = t;
      drift = driftAt();
    }
    if (bad > 0.0) {
      for (std::uint32_t h = 0; h < settings.halvings; ++h) {
        const double t = 0.5 * (good + bad);
        fields.at(c.point + t * out, fa, fb);
        ++queries;
        if (walk.holds(fa, fb)) {
          good = t;
          drift = driftAt();
        } else {
          bad = t;
        }
      }
    }
    // Past a rim a field rises about as fast as the walk goes: a probe that held may lie as far
    // beyond it as the fields changed there, where the normal line through the point misses a
    // body. Step back by that change.
    if (bad > 0.0) good -= drift;
    if (good > 0.0) {
      c.point += good * out;
      c.errorBound += drift;  // the depth holds there within the fields' change
    }
  }
  return queries;
}

}  // namespace clod
