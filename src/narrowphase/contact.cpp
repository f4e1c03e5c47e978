#include "clod/contact.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <utility>

#include "clod/error.h"
#include "narrowphase/support_polygon.h"

namespace clod {
namespace {

// Depths within this fraction of the deepest count as equally deep (reduceManifold): far above
// rounding (a vertex's depth from two models' arithmetic differed by ~1e-12 relative), far below
// any depth difference the solver could act on.
constexpr double kDepthTieRel = 1e-6;
// ... and so do depths within this fraction of the contacts' extent: the contact tree's samples of
// a face lying flat differ by field noise (~3e-6 of the face's size at 3e-8 m deep, far more than
// 1e-6 of the depth), and the deepest of them was an interior sample picked by that noise. The
// same tolerance as the support polygon's depth plane (narrowphase/support_polygon.cpp).
constexpr double kDepthTieExtentRel = 1e-4;

constexpr std::array<ContactModel, 5> kModels = {ContactModel::kDos, ContactModel::kAverage, ContactModel::kCfm,
                                                 ContactModel::kContactTree, ContactModel::kExact};

}  // namespace

std::span<const ContactModel> allContactModels() noexcept { return kModels; }

std::string_view contactModelName(ContactModel model) noexcept {
  switch (model) {
    case ContactModel::kDos: return "dos";
    case ContactModel::kAverage: return "average";
    case ContactModel::kCfm: return "cfm";
    case ContactModel::kContactTree: return "contact-tree";
    case ContactModel::kExact: return "exact";
  }
  return "unknown";
}

ContactModel parseContactModel(std::string_view name) {
  for (ContactModel m : kModels) {
    if (contactModelName(m) == name) return m;
  }
  throw Error(ErrorCode::kInvalidArgument,
              "unknown contact model '" + std::string(name) + "' (valid: dos, average, cfm, contact-tree, exact)");
}

std::size_t reduceManifold(std::span<Contact> contacts, const ManifoldSettings& settings, std::vector<double>& scratch) {
  if (settings.maxContacts == 0) throw Error(ErrorCode::kInvalidArgument, "manifold maxContacts must be >= 1");
  if (!(settings.mergeDistanceAbs >= 0.0) || !std::isfinite(settings.mergeDistanceAbs)) {
    throw Error(ErrorCode::kInvalidArgument, "manifold mergeDistanceAbs must be finite and >= 0");
  }
  const std::size_t n = contacts.size();
  if (n == 0) return 0;

  // Deepest first. Among contacts as deep within kDepthTieRel or kDepthTieExtentRel (a face or an
  // edge lying flat on another: many equal depths, which differ only by rounding or field noise),
  // the one farthest from the contacts' centroid: an end of the edge, a corner of the face.
  // Before, input order broke the tie, so two models that found the same vertices of a fandisk's
  // edge lying flat on a box kept different subsets -- one without the edge's end -- and the drop
  // turned differently.
  std::size_t strict = 0;
  for (std::size_t i = 1; i < n; ++i) {
    if (contacts[i].depth > contacts[strict].depth) strict = i;
  }
  // Distances are measured in the contact plane so that contacts stacked along the normal (the
  // same spot seen at different depths) count as one, and spread means spread along the surface.
  const Vec3 normal = contacts[strict].normal;
  auto planar = [&](const Vec3& d) { return (d - normal.dot(d) * normal).squaredNorm(); };
  // Two contacts one spot apart in that plane are one spot only if both face it (within 45
  // deg): a face's contacts beside a deeper one on a perpendicular face (a cube on a slab with a
  // block pressing its side) lie on one line along the deeper normal yet are opposite corners of
  // the face. The squared distance that decides it: in the plane, or whole where either turns away.
  constexpr double kSamePlaneCos = 0.70710678118654752;
  auto apart = [&](std::size_t i, std::size_t k) {
    const Vec3 d = contacts[i].point - contacts[k].point;
    const bool facing = contacts[i].normal.dot(normal) >= kSamePlaneCos && contacts[k].normal.dot(normal) >= kSamePlaneCos;
    return facing ? planar(d) : d.squaredNorm();
  };
  Vec3 centroid = Vec3::Zero();
  for (std::size_t i = 0; i < n; ++i) centroid += contacts[i].point;
  centroid /= static_cast<double>(n);
  double reach = 0.0;  // the contacts' largest squared distance from their centroid, in the plane
  for (std::size_t i = 0; i < n; ++i) reach = std::max(reach, planar(contacts[i].point - centroid));
  const double tieDepth = contacts[strict].depth - std::max(kDepthTieRel * std::abs(contacts[strict].depth),
                                                            kDepthTieExtentRel * 2.0 * std::sqrt(reach));
  std::size_t deepest = strict;
  double deepestSpread = planar(contacts[strict].point - centroid);
  for (std::size_t i = 0; i < n; ++i) {
    if (contacts[i].depth < tieDepth) continue;
    const double spread = planar(contacts[i].point - centroid);
    if (spread > deepestSpread) deepest = i, deepestSpread = spread;
  }
  std::swap(contacts[0], contacts[deepest]);

  // scratch[i]: squared planar distance of contact i to the kept set (the scores);
  // scratch[n + i]: its squared `apart` distance (whether it merges into a kept one).
  // scratch[2n ..): the support polygon's room (3 per kept contact).
  const std::size_t polygonRoom = 3 * std::min<std::size_t>(settings.maxContacts, n);
  scratch.resize(2 * n + polygonRoom);
  double* whole = scratch.data() + n;
  for (std::size_t i = 1; i < n; ++i) scratch[i] = planar(contacts[i].point - contacts[0].point), whole[i] = apart(i, 0);
  const double mergeSquared = settings.mergeDistanceAbs * settings.mergeDistanceAbs;
  std::size_t kept = 1;
  // Moves contact `chosen` into the kept prefix and lowers the others' distances to the kept set.
  auto keep = [&](std::size_t chosen) {
    // Keep the order of the not-yet-kept contacts stable enough for deterministic ties: swap the
    // chosen one into place (ties were resolved by input order in the scans).
    std::swap(contacts[kept], contacts[chosen]);
    std::swap(scratch[kept], scratch[chosen]);
    std::swap(whole[kept], whole[chosen]);
    for (std::size_t i = kept + 1; i < n; ++i) {
      scratch[i] = std::min(scratch[i], planar(contacts[i].point - contacts[kept].point));
      whole[i] = std::min(whole[i], apart(i, kept));
    }
    ++kept;
  };
  // The index of the largest score among the not-kept contacts farther than the merge distance
  // from every kept one (n: none with a positive score).
  // (A contact within the merge distance of a kept one in the plane but no duplicate by `apart`
  // is scored by its `apart` distance.)
  auto best = [&](auto score) {
    std::size_t chosen = n;
    double top = 0.0;
    for (std::size_t i = kept; i < n; ++i) {
      if (whole[i] <= mergeSquared) continue;
      const double distance = scratch[i] <= mergeSquared ? whole[i] : scratch[i];
      const double value = score(i, distance);
      if (value > top) top = value, chosen = i;
    }
    return chosen;
  };
  auto farthest = [](std::size_t, double distance) { return distance; };
  if (kept < settings.maxContacts && kept < n) {
    const std::size_t second = best(farthest);
    if (second < n) keep(second);
  }
  // Then the two contacts farthest from the line through those, one on each side: with the first
  // two near opposite corners of a face-on-face overlap these are its other two corners, where
  // farthest-point picks preferred the middle of a long side (an overlap 0.7 x 1 kept no contact
  // within 23 cm of two of its corners).
  if (kept == 2) {
    const Vec3 p0 = contacts[0].point, axis = contacts[1].point - p0;
    for (double side : {1.0, -1.0}) {
      if (kept >= settings.maxContacts) break;
      const std::size_t chosen =
          best([&](std::size_t i, double) { return side * axis.cross(contacts[i].point - p0).dot(normal); });
      if (chosen < n) keep(chosen);
    }
  }
  // Then picks that add support area or depth (narrowphase/support_polygon.h): the contact farthest
  // outside the support polygon of the kept ones, or farthest from them among those that lie deeper
  // than the polygon's depth plane, or -- where the polygon has no say (a wall's contacts beside a
  // floor's, a curved patch) -- farthest from them. A contact inside the polygon and no deeper
  // adds nothing the solver can use, only another point to share the load: a face lying on a face
  // is held at the corners of the overlap, not at interior samples. The contact tree's samples of
  // a flat face differ in depth by field noise far below their bounds, and farthest-point picks
  // among them followed that noise, so the load -- and the friction of a box spinning on the
  // floor -- was uneven and the box drifted 12 cm where the exact model's stood still.
  detail::SupportPolygon polygon(normal, {scratch.data() + 2 * n, polygonRoom});
  for (std::size_t k = 0; k < kept; ++k) polygon.add(contacts[k]);
  while (kept < settings.maxContacts && kept < n) {
    polygon.close();
    const std::size_t chosen =
        best([&](std::size_t i, double distance) { return polygon.pickScore(contacts[i], distance); });
    if (chosen == n) break;
    keep(chosen);
    polygon.add(contacts[kept - 1]);
  }
  if (settings.poolNormalsCos <= 1.0 && kept < n) {
    // scratch[kept .. n) are free (distances of the not-kept contacts are recomputed per kept
    // contact below); the sums go after them: 4 doubles per kept contact (x, y, z, weight).
    scratch.resize(2 * n + 4 * kept);
    double* sums = scratch.data() + 2 * n;
    for (std::size_t k = 0; k < kept; ++k) {
      const double w = std::max(contacts[k].depth, 0.0);
      sums[4 * k + 0] = w * contacts[k].normal.x();
      sums[4 * k + 1] = w * contacts[k].normal.y();
      sums[4 * k + 2] = w * contacts[k].normal.z();
      sums[4 * k + 3] = w;
    }
    bool anyWeight = false;
    for (std::size_t k = 0; k < kept; ++k) anyWeight = anyWeight || sums[4 * k + 3] > 0.0;
    for (std::size_t i = kept; i < n; ++i) {
      std::size_t nearest = kept;
      double nearestDistance = std::numeric_limits<double>::infinity();
      for (std::size_t k = 0; k < kept; ++k) {
        if (contacts[i].normal.dot(contacts[k].normal) < settings.poolNormalsCos) continue;
        const double d = planar(contacts[i].point - contacts[k].point);
        if (d < nearestDistance) {
          nearestDistance = d;
          nearest = k;
        }
      }
      if (nearest == kept) continue;
      const double w = std::max(contacts[i].depth, 0.0);
      anyWeight = anyWeight || w > 0.0;
      sums[4 * nearest + 0] += w * contacts[i].normal.x();
      sums[4 * nearest + 1] += w * contacts[i].normal.y();
      sums[4 * nearest + 2] += w * contacts[i].normal.z();
      sums[4 * nearest + 3] += w;
    }
    if (anyWeight) {
      for (std::size_t k = 0; k < kept; ++k) {
        const Vec3 sum(sums[4 * k + 0], sums[4 * k + 1], sums[4 * k + 2]);
        const double length = sum.norm();
        // A kept contact of depth <= 0 with only such contacts assigned keeps its own normal.
        if (sums[4 * k + 3] > 0.0 && length > 1e-12 * sums[4 * k + 3]) contacts[k].normal = sum / length;
      }
    }
  }
  return kept;
}

}  // namespace clod
