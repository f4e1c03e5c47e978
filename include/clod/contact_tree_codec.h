#pragma once
// Binary encoding of a contact tree, for the contact-tree section of the bake file.
//
// Layout (little-endian, ByteWriter conventions; version 2):
//   u32 version, f64 origin[3], f64 rootSize, f64 meshDiagonal, f64 errorAbs, f64 bandAbs,
//   u32 maxDepth, f32 rootCorners[8], then arrays (u64 count + elements): levelOffsets (u32),
//   interior bitmap (u64, one bit per node), surface bitmap (u64), errorCode (u16),
//   lattice (f32), halfSpaces (20-byte records: f32 normal[3], f32 offset, f32 fitError).
// The rank counts of ContactTree::nodeWords are derived on decoding. Version 1 (32-bit child
// and half-space indices, f32 error bounds) is refused with kBakeVersion: re-bake.

#include "clod/byte_stream.h"
#include "clod/contact_tree.h"

namespace clod {

/// Version written by encodeContactTree and the only one decodeContactTree accepts.
inline constexpr std::uint32_t kContactTreeCodecVersion = 2;

/// Appends `tree` to `out`. Precondition: the tree came from buildContactTree or
/// decodeContactTree (its invariants hold). Deterministic: equal trees give equal bytes.
void encodeContactTree(const ContactTree& tree, ByteWriter& out);

/// Reads a tree written by encodeContactTree, consuming exactly its bytes. Validates every
/// field, count, index and offset before returning, so that every query on the result is
/// memory-safe: throws kBakeTruncated when the data ends early, kBakeVersion for another
/// version, and kBakeCorrupt naming the field (e.g. "contact tree: firstChild[17] = 9 breaks
/// the breadth-first layout, expected 25") for anything inconsistent, including non-finite
/// values. O(size of the tree).
ContactTree decodeContactTree(ByteReader& in);

}  // namespace clod
