#pragma once
// The support polygon of a manifold: where a contact adds nothing. A face lying on a face is held
// by the corners of the overlap; a contact inside their polygon, no deeper than they say it should
// be, adds no support area and no depth -- only one more point to share the load, and the share it
// takes follows the order of the solver's sweeps and the noise in the depths, not the geometry.
// reduceManifold (contact.cpp) and the world's persistent manifold (world.cpp) use it to leave such
// contacts out (docs/narrow-phase.md, "Manifold").

#include <array>
#include <cstddef>
#include <span>

#include "clod/contact.h"

namespace clod::detail {

class SupportPolygon {
 public:
  /// An empty polygon in the plane perpendicular to `normal` (unit), kept in `buffer`: room for
  /// buffer.size() / 3 contacts.
  SupportPolygon(const Vec3& normal, std::span<double> buffer);

  /// Adds a contact if it faces `normal`'s way (normals within 1 deg); others are ignored, as a
  /// wall's contacts beside a floor's, or a curved patch's. Contacts past the buffer's room are ignored too.
  void add(const Contact& c);

  /// Finishes the polygon: the convex hull of the added contacts and the least-squares plane of
  /// their depths over it. Contacts may be added after it, and it called again. False where they span no area (fewer than three, or all near one line):
  /// then addsNothing is false for every contact.
  bool close();

  /// How much keeping contact `c` adds, as a pick score for the manifold reduction (0: nothing):
  ///  - `spread` where the polygon has no say: it is not closed, or c does not face its way;
  ///  - how far c lies outside the polygon, where that is more than 1 % of its extent: the support
  ///    area it adds grows with it, so the corners of the overlap come first;
  ///  - `spread` for a contact inside it (or on its rim) but deeper than the depth plane there
  ///    by more than 1e-4 of its extent: it adds depth;
  ///  - 0 for the rest.
  double pickScore(const Contact& c, double spread) const;
  bool addsNothing(const Contact& c) const { return pickScore(c, 1.0) == 0.0; }

 private:
  double x(std::size_t i) const { return points_[2 * i]; }
  double y(std::size_t i) const { return points_[2 * i + 1]; }
  std::size_t hullPoint(std::size_t k) const { return static_cast<std::size_t>(hull_[k]); }
  void wrapHull();
  double twiceHullArea() const;
  bool fitDepthPlane();

  Vec3 normal_, u_, v_;
  Vec3 origin_ = Vec3::Zero();  // the first added contact's point: coordinates relative to it
  double* points_;  // x, y per added contact
  double* hull_;    // the hull's point indices, counter-clockwise
  std::size_t room_, count_ = 0, hullSize_ = 0;
  double extent_ = 0.0;
  bool closed_ = false;
  // Sums for the depth plane d = c0 + c1 x + c2 y: the normal equations' matrix (upper half) and
  // right-hand side.
  std::array<double, 6> moments_{};
  std::array<double, 3> depthMoments_{};
  std::array<double, 3> plane_{};
};

}  // namespace clod::detail
