#pragma once
// Closed, outward-oriented triangle meshes of non-convex parts, for the demos where a convex
// hull is visibly wrong: a ring (torus) to drop over a peg, a bowl to catch a body, a block with
// a hole to insert a peg into (docs/engines-mujoco.md, scenes/mujoco/). A peg is makeCylinder
// (primitives.h). Same conventions as primitives.h: counter-clockwise seen from outside, manifold,
// one component, no degenerate triangles, every quad of the parametrisation planar; invalid
// parameters (non-finite or non-positive sizes, counts out of range, a hole that does not fit)
// throw clod::Error(kInvalidArgument) naming the parameter.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "clod/mesh.h"

namespace clod {

/// Torus around the z axis, centred at the origin: the circle of `minorRadius` (a regular
/// polygon of `minorSegments` vertices at that distance, the first on the outer equator) swept
/// around the circle of `majorRadius` in the xy plane (`majorSegments` cross-sections, the first
/// at angle 0 on +x). minorRadius < majorRadius, 3 <= segments <= 65536.
/// majorSegments x minorSegments vertices, twice as many triangles; genus 1.
/// Volume, exactly (each segment is a sheared prism over the polygon):
///   majorSegments sin(2 pi / majorSegments) * (minorSegments / 2) minorRadius^2 sin(2 pi / minorSegments) * majorRadius.
/// O(triangles).
TriangleMesh makeTorus(double majorRadius, double minorRadius, std::uint32_t majorSegments,
                       std::uint32_t minorSegments);

/// Hemispherical bowl, opening upward: the shell between the spheres of `outerRadius` and
/// `outerRadius - thickness` about the origin, below the plane z = 0 (rim at z = 0, bottom at
/// z = -outerRadius). Each hemisphere is `rings` latitude bands from the rim down to its pole
/// (a triangle fan there), `segments` vertices around (first on +x); the rim is the flat annulus
/// at z = 0. 0 < thickness < outerRadius, 3 <= segments <= 65536, 2 <= rings <= 4096.
/// 2 (segments x rings + 1) vertices, 4 x segments x rings triangles; genus 0. The vertices lie
/// on the spheres (inscribed), so the volume is a little below (2/3) pi (R^3 - r^3).
/// O(triangles).
TriangleMesh makeBowl(double outerRadius, double thickness, std::uint32_t segments, std::uint32_t rings);

/// Box with the given half extents, centred at the origin, with a cylindrical through-hole of
/// `holeRadius` along z (a regular polygon of `segments` vertices at that distance, the first
/// at angle 0 on +x, inscribed). The top and bottom faces are annuli between the square and the
/// hole: each hole vertex is joined to the point of the box's side where the ray from the axis
/// through it leaves the box, so segments must be a multiple of 8 (the box's corners are then
/// among those points), 8 <= segments <= 65536, and the hole must fit: holeRadius < min(half
/// extents x, y). 4 x segments vertices, 8 x segments triangles; genus 1.
/// Volume, exactly: 8 hx hy hz - 2 hz (segments / 2) holeRadius^2 sin(2 pi / segments). O(segments).
TriangleMesh makeHoledBlock(const Vec3& halfExtents, double holeRadius, std::uint32_t segments);

/// A named mesh, for writing parts to files.
struct NamedMesh {
  std::string name;  ///< file stem, e.g. "ring"
  TriangleMesh mesh;
};

/// The parts of the MuJoCo demos in scenes/mujoco/ (`clod generate mujoco-demo -o DIR` writes
/// them as DIR/<name>.obj; metres):
///   ring        torus, major radius 25 mm, minor 5 mm (hole radius 20 mm), 48 x 12
///   ring_peg    cylinder, radius 12 mm, height 100 mm, 32 sides
///   bowl        bowl, outer radius 90 mm, wall 6 mm, 48 x 12
///   holed_block block 60 x 60 x 40 mm with a through-hole of radius 10.5 mm, 64 sides
///   hole_peg    cylinder, radius 10 mm (1 mm less than the hole's diameter), height 60 mm, 32 sides
std::vector<NamedMesh> demoPartMeshes();

/// The mesh as Wavefront OBJ text: `comment` as '#' lines (may be empty), then one "v x y z"
/// line per vertex (the shortest decimal form that reads back to the same double, std::to_chars), then one
/// "f a b c" line per triangle (1-based). Deterministic. O(size).
std::string encodeObj(const TriangleMesh& mesh, std::string_view comment = {});

}  // namespace clod
