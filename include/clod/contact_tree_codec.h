#pragma once
// Binary encoding of a contact tree, for the contact-tree section of the bake file.
//
// Layout (little-endian, ByteWriter conventions; version 6, docs/bake-format.md has the table):
//   u32 version, f64 origin[3], f64 rootSize, f64 meshDiagonal, f64 errorAbs, f64 bandAbs,
//   u32 maxDepth, f32 rootCorners[8], u32 node count, u32 depth count, then one array (u64
//   count + bytes): the nodes in breadth-first order, range-coded with adaptive binary models
//   (src/contact_tree/range_coder.h). What the corners of a node prove (ContactTree::provenFar)
//   is not stored: such a node is a leaf without a half-space and with farErrorCode. For every
//   other node: split bit (not at maxDepth), surface bit, the error code (one bit for the
//   Lipschitz cap farErrorCode, else its 7 + 4 bits: exponent and 3 mantissa bits); for a split
//   node its 19 lattice values as integers of ContactTree::valueStep(), each minus the trilinear
//   prediction from the node's corners -- but a point on its boundary that a neighbour of the
//   same depth coded before is one bit, "the same value"; for a surface cell the half-space's octahedral normal
//   code minus that of the trilinear gradient, its offset (units of halfSpaceStep()) minus the
//   centre value, and its fit error. Lossless for trees from buildContactTree, which rounds
//   every value onto these grids (the encoder refuses any other tree with kInvalidArgument).
//   Versions 1 and 2 (uncompressed arrays of floats), 3 (the first coding, without the cap
//   bit and the lattice contexts), 4 (error codes with 7 mantissa bits, normals in steps of
//   1/32767) and 5 (every lattice value coded by every node that holds it) are refused with
//   kBakeVersion: re-bake.

#include "clod/byte_stream.h"
#include "clod/contact_tree.h"

namespace clod {

/// Version written by encodeContactTree and the only one decodeContactTree accepts.
inline constexpr std::uint32_t kContactTreeCodecVersion = 6;

/// Appends `tree` to `out`. The tree must come from buildContactTree or decodeContactTree:
/// a tree whose shape is inconsistent or whose values are not on the codec's grids (or whose
/// proven-far nodes are not the leaves the decoder would derive) is refused with
/// clod::Error(kInvalidArgument) naming the node. Deterministic: equal trees give equal bytes.
/// O(nodes).
void encodeContactTree(const ContactTree& tree, ByteWriter& out);

/// Reads a tree written by encodeContactTree, consuming exactly its bytes. Validates every
/// field, count, index and offset before returning, so that every query on the result is
/// memory-safe: throws kBakeTruncated when the data ends early, kBakeVersion for another
/// version, and kBakeCorrupt naming the field (e.g. "contact tree: firstChild[17] = 9 breaks
/// the breadth-first layout, expected 25") for anything inconsistent, including non-finite
/// values. O(size of the tree).
ContactTree decodeContactTree(ByteReader& in);

}  // namespace clod
