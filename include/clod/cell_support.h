#pragma once
// Support points of a contact tree's coarse cells: for each surface cell down to a depth, the
// points of the mesh's surface inside the cell (the triangles clipped to the cube) that lie
// farthest along each of 386 directions (a 9 x 9 grid on each face of a cube) and the vertices
// of that clipped surface's convex hull (so every direction's farthest point is among them),
// without repeats.
//
// Why: an interrupted contact-tree query answers from coarse cell pairs, whose samples -- a
// lattice on the cell's plane, moved onto the surface -- are spread over the whole cell and
// miss a small contact region: a bunny on a floor touches with a few centimetres of its 0.6 m
// body, a fandisk with one corner. The region where a body enters another is where it reaches
// farthest toward it, i.e. near a support point of its cell in the direction of the other
// body's normal; a box cell's support points are its corners. Tested against the other body's
// field they give the deepest points of the coarse answer with the field's accuracy, whatever
// the level (docs/contact-tree.md, "Support points"). A query interrupted at its budget tests
// them on its coarse pairs (ContactSamplingSettings::supportPoints), and every query answers a
// pair whose other cell is flat with them (ContactSamplingSettings::flatPartnerSupports).
//
// Derived data, like the lookup grid: not in the bake file, rebuilt from the body's mesh when a
// CollisionBody receives its contact tree.

#include <cstdint>
#include <span>

#include "clod/contact_tree.h"
#include "clod/mesh.h"

namespace clod {

/// Deepest depth whose cells get support points: the levels an interrupted query answers from
/// (16-256 tests per frame stop at depths 1-4).
inline constexpr std::uint32_t kCellSupportMaxDepth = 4;

/// Fills tree.supportOffsets / tree.supportPoints from `mesh` (the mesh the tree was built for,
/// in the same frame) for every node of depth <= maxDepth. O(triangles x cells they cross).
void deriveCellSupports(ContactTree& tree, const TriangleMesh& mesh, std::uint32_t maxDepth = kCellSupportMaxDepth);

}  // namespace clod
