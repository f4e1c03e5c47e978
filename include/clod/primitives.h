#pragma once
// Closed, outward-oriented triangle meshes of primitives, for tests and scenes.
// All are centred at the origin.

#include <cstdint>

#include "clod/mesh.h"

namespace clod {

/// Axis-aligned box with the given half extents (12 triangles, 8 vertices).
TriangleMesh makeBox(const Vec3& halfExtents);

/// Icosphere: an icosahedron subdivided `subdivisions` times, vertices projected onto the
/// sphere of `radius` (20 * 4^subdivisions triangles).
TriangleMesh makeIcosphere(double radius, std::uint32_t subdivisions);

/// Cylinder along z from -halfHeight to +halfHeight with `segments` sides, capped.
TriangleMesh makeCylinder(double radius, double halfHeight, std::uint32_t segments);

}  // namespace clod
