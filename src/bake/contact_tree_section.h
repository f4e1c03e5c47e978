#pragma once
// The 'CTRE' section of a bake file: the contact tree of the bake's mesh (contact_tree.h).
// Optional: bakes without it load with no contact tree.
//
// Payload, version 1: exactly the bytes of encodeContactTree (contact_tree_codec.h; that
// encoding carries its own inner version, also 1), nothing before or after. The tree must have
// been built for the bake's mesh: its meshDiagonal equals the mesh's bounding-box diagonal bit
// for bit and its root cube contains the mesh's bounding box (checked on write and on read).

#include <cstddef>
#include <span>
#include <vector>

#include "clod/contact_tree.h"
#include "clod/mesh.h"
#include "section_codec.h"

namespace clod::detail {

/// Checks that `tree` decodes (every invariant of decodeContactTree) and belongs to `mesh`
/// (see above); calls `complain` naming the field otherwise.
void checkContactTree(const ContactTree& tree, const TriangleMesh& mesh, const Complaint& complain);

/// Encodes a tree (which checkContactTree has accepted).
std::vector<std::byte> encodeContactTreeSection(const ContactTree& tree);

/// Decodes a 'CTRE' payload of version 1 for `mesh` and checks it. Throws kBakeTruncated /
/// kBakeVersion / kBakeCorrupt naming the section and field.
ContactTree decodeContactTreeSection(std::span<const std::byte> payload, const TriangleMesh& mesh);

}  // namespace clod::detail
