#pragma once
// Closed, outward-oriented triangle meshes of primitives, for tests and scenes.
// All are centred at the origin, counter-clockwise seen from outside, manifold, one component,
// no degenerate triangles. Invalid parameters (non-positive or non-finite sizes, counts out of
// range) throw clod::Error(kInvalidArgument) naming the parameter: scene files pass them through.

#include <cstdint>

#include "clod/mesh.h"

namespace clod {

/// Axis-aligned box with the given half extents (12 triangles, 8 vertices). Vertex i has
/// coordinate signs (+x if i&1, +y if i&2, +z if i&4). O(1).
TriangleMesh makeBox(const Vec3& halfExtents);

/// Icosphere: an icosahedron subdivided `subdivisions` times, vertices projected onto the
/// sphere of `radius` (20 * 4^subdivisions triangles, 10 * 4^subdivisions + 2 vertices, all at
/// distance `radius` from the origin up to rounding). The polyhedron is inscribed in the sphere,
/// so its volume is slightly smaller (-0.86 % at 3 subdivisions, -0.054 % at 5; the deficit
/// shrinks 4x per subdivision).
/// subdivisions <= 10. O(triangles) time and memory.
TriangleMesh makeIcosphere(double radius, std::uint32_t subdivisions);

/// The mesh of a ball body (RigidBodyDesc::ballRadius): makeIcosphere scaled so that every face's
/// plane is at least `radius` from the origin, a polyhedron that encloses the ball (its vertices
/// reach 1.8 % beyond it at 2 subdivisions). Same limits as makeIcosphere.
TriangleMesh makeBallHull(double radius, std::uint32_t subdivisions);

/// Cylinder along z from -halfHeight to +halfHeight with `segments` sides (3 <= segments <= 2^28),
/// capped by triangle fans around a centre vertex: 2 * segments + 2 vertices, 4 * segments
/// triangles. Ring vertices lie on the circle of `radius` (an inscribed regular prism), the first
/// at angle 0 on +x. O(segments).
TriangleMesh makeCylinder(double radius, double halfHeight, std::uint32_t segments);

}  // namespace clod
