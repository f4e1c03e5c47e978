#pragma once
// Mass properties of a closed triangle mesh treated as a solid of uniform density: volume,
// centre of mass and inertia tensor, by the exact polyhedral integrals.
//
// Method: the divergence theorem turns each volume integral into a sum over triangles; for a
// triangle (a, b, c) that is the integral over the signed tetrahedron (o, a, b, c), for which
// closed forms exist (Tonon, "Explicit exact formulas for the 3-D tetrahedron inertia tensor
// in terms of its vertex coordinates", J. Math. Stat. 1(1), 2004; equivalent to Mirtich,
// "Fast and accurate computation of polyhedral mass properties", JGT 1(2), 1996). The result
// is exact up to floating-point rounding for any closed, consistently oriented mesh, convex
// or not. The reference point o is moved to the bounding-box centre first, which keeps the
// rounding error relative to the mesh size, not to its distance from the origin.

#include "clod/math.h"
#include "clod/mesh.h"

namespace clod {

struct MassProperties {
  double volume = 0.0;        ///< enclosed volume, > 0 (mesh units^3)
  double mass = 0.0;          ///< density * volume
  Vec3 centerOfMass = Vec3::Zero();  ///< in mesh coordinates
  /// Inertia tensor about the centre of mass, axes parallel to the mesh axes (mass * units^2):
  /// I = integral of rho * (|r|^2 Id - r r^T) dV with r measured from centerOfMass. Symmetric
  /// positive definite for any solid.
  Mat3 inertia = Mat3::Zero();
};

/// Computes the mass properties of the solid bounded by `mesh`.
///
/// Requirements (checked; each failure throws clod::Error with kUnsupportedMesh and a message
/// saying which): the mesh is closed (every edge shared by exactly two triangles, no boundary
/// and no non-manifold edge), consistently oriented, with non-zero enclosed volume. Fatal mesh
/// problems (NaN, out-of-range indices, no triangles) throw their own codes as in
/// requireValidMesh. Open meshes have no enclosed volume, so there is no meaningful answer to
/// return: this function throws rather than guessing (the CLI prints `volume: null`).
/// An inside-out mesh (negative signed volume) is accepted and treated as if it were flipped:
/// the solid is the same. `density` must be > 0 and finite (else kInvalidArgument).
///
/// Complexity: O(T log T) for the closedness check (edge sort) plus O(T) for the integrals.
MassProperties computeMassProperties(const TriangleMesh& mesh, double density = 1.0);

/// As computeMassProperties for a closed mesh; an open mesh (no enclosed volume, e.g. a scan
/// with holes such as bunny-1500) gets those of the solid box of its bounds instead, so a body
/// made from it still has a plausible mass and inertia. Other errors propagate.
MassProperties computeMassPropertiesOrBoundingBox(const TriangleMesh& mesh, double density = 1.0);

/// The solid ball of `radius` (> 0 and finite, else kInvalidArgument) about the origin:
/// volume 4/3 pi r^3, centre at the origin, inertia 2/5 m r^2 on every axis.
MassProperties ballMassProperties(double radius, double density = 1.0);

}  // namespace clod
