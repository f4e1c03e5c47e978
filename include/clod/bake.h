#pragma once
// Bake files (.clod): everything clod precomputes for one mesh, in one checked binary file,
// so an engine loads assets instead of rebuilding them. A bake holds the mesh, its
// sphere-tree, and optionally the closest feature maps and the contact tree; each is a
// section, and readers skip sections they do not know, so later sections can be added.
//
// Typical use:
//   BakeResult baked = bakeMesh(loadMesh("bunny.obj").mesh, settings);   // minutes at most
//   saveBake("bunny.clod", baked.contents);                               // atomic
//   BakeContents contents = loadBake("bunny.clod");                       // milliseconds
//
// Byte layout: docs/bake-format.md; the container (header, section table, checksums) is in
// bake_file.h. Every function that reads bytes treats them as untrusted: a truncated,
// corrupted or newer file throws clod::Error and never crashes or returns wrong content.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "clod/bake_file.h"
#include "clod/closest_feature_map.h"
#include "clod/contact_tree.h"
#include "clod/contact_tree_builder.h"
#include "clod/error.h"
#include "clod/mesh.h"
#include "clod/proximity.h"
#include "clod/sphere_tree.h"
#include "clod/sphere_tree_builder.h"

namespace clod {

/// Section tags and the newest version of each that this build writes and reads.
inline constexpr BakeSectionTag kBakeMeshTag = makeBakeSectionTag("MESH");
inline constexpr std::uint32_t kBakeMeshVersion = 1;
inline constexpr BakeSectionTag kBakeSphereTreeTag = makeBakeSectionTag("STRE");
/// Version 2: quantised, range-coded (version 1, plain f64 arrays, is refused: re-bake).
inline constexpr std::uint32_t kBakeSphereTreeVersion = 2;
/// Closest feature maps of the sphere-tree (optional; layout in src/bake/cfm_section.h).
inline constexpr BakeSectionTag kBakeCfmTag = makeBakeSectionTag("CFMP");
/// Version 2: range-coded (version 1, plain arrays, is refused: re-bake).
inline constexpr std::uint32_t kBakeCfmVersion = 2;
/// The contact tree of the mesh (optional; payload = encodeContactTree, contact_tree_codec.h;
/// layout in src/bake/contact_tree_section.h and docs/bake-format.md).
inline constexpr BakeSectionTag kBakeContactTreeTag = makeBakeSectionTag("CTRE");
inline constexpr std::uint32_t kBakeContactTreeVersion = 1;

/// 64-bit content hash of a mesh, for cache keys and to tie a bake to its mesh: XXH3-64
/// (seed 0) over the vertex count and triangle count (u64 each), then every vertex coordinate
/// (f64, x y z per vertex), then every triangle index (u32, three per triangle), all
/// little-endian. Any change of a coordinate bit or an index changes it (with overwhelming
/// probability); -0.0 and +0.0 hash differently. O(V + T), a few GB/s.
std::uint64_t meshContentHash(const TriangleMesh& mesh) noexcept;

/// Everything a bake file holds. Plain data; equal contents encode to identical bytes.
/// Sections added by later issues become further members (optional ones may be absent).
struct BakeContents {
  /// The mesh the rest was built from, in its own coordinates. Required ('MESH').
  TriangleMesh mesh;
  /// meshContentHash(mesh). Set by decodeBake/loadBake and bakeMesh; encodeBake ignores this
  /// field and always stores the hash of `mesh`, so a stale value can never reach a file.
  std::uint64_t meshHash = 0;
  /// Where the mesh came from (e.g. its file name), for humans; may be empty. ('MESH')
  std::string sourceName;

  /// The sphere-tree and the settings it was built with. Required ('STRE'). The file stores
  /// sphere values on a power-of-two grid of at most 2^-11 of the parent's radius, radii rounded
  /// up: a tree from elsewhere decodes with every ball containing its original and grown by
  /// < 0.092 % of its parent's radius; a tree from bakeMesh or decodeBake is already on the grid
  /// and survives bit for bit (docs/bake-format.md, 'STRE' version 2).
  SphereTree sphereTree;
  SphereTreeSettings sphereTreeSettings;

  /// Closest feature maps of sphereTree (optional, 'CFMP'). Must have been built for
  /// sphereTree (encodeBake re-checks it with ClosestFeatureMap::fromData: kInvalidArgument).
  std::optional<ClosestFeatureMap> closestFeatureMap;

  /// Contact tree (adaptive signed distance field) of `mesh` (optional, 'CTRE'). Must have been
  /// built for `mesh`: its meshDiagonal equal to mesh.bounds().diagonal() bit for bit and its
  /// root cube containing the mesh's bounding box (encodeBake checks this and every invariant
  /// of decodeContactTree: kInvalidArgument).
  std::optional<ContactTree> contactTree;
};

/// Encodes contents as a complete bake file. Deterministic: equal contents give identical
/// bytes, and encodeBake(decodeBake(bytes)) == bytes for every file this function wrote.
/// Lossless except for sphere values not yet on the file's grid (see BakeContents::sphereTree).
/// O(size of the contents).
///
/// Checks first that the contents can be decoded again and throws
/// clod::Error(kInvalidArgument) naming the field otherwise (non-finite coordinates, triangle
/// indices >= vertex count, an inconsistent sphere-tree or one that does not bound the mesh:
/// see decodeBake for the list, or
/// more than 2^32-1 of anything), so no file that loadBake would reject is ever written.
std::vector<std::byte> encodeBake(const BakeContents& contents);

/// Decodes a bake file held in memory. Besides the container checks (bake_file.h), checks
/// every semantic invariant before returning, and throws clod::Error(kBakeCorrupt) naming the
/// section and field when one fails: mesh coordinates finite, triangle indices < vertex
/// count, stored mesh hash == meshContentHash of the decoded mesh; sphere-tree arrays sized
/// consistently with the sphere count, levelOffsets starting at 0 with one root sphere and
/// strictly increasing to the sphere count, centres finite, radii finite and >= 0, parent and
/// child ranges pointing into the neighbouring levels and agreeing with each other,
/// triangleOffsets monotone from 0 to the triangle list size, triangle indices < the mesh's
/// triangle count, a known method; the spheres bounding the mesh (the root contains every
/// triangle corner; on every level, every triangle is listed and each corner of a listed
/// triangle lies in some sphere of the level listing it; tolerance 1e-6 of the bounding-box
/// diagonal; the error names the sphere and its level); closest feature maps consistent with the sphere-tree
/// (ClosestFeatureMap::fromData); a contact tree passing decodeContactTree's checks, with no
/// bytes after it, and belonging to the mesh (see BakeContents::contactTree). Other errors: kBakeTruncated, kBakeVersion (the file or a
/// known section is newer than this build), kBakeMissingSection ('MESH' or 'STRE' absent).
/// Sections with unknown tags are skipped. O(file size).
BakeContents decodeBake(std::span<const std::byte> bytes);

/// Writes a bake file atomically (temporary file in the same directory, then rename): a crash
/// or failure never leaves a partial file at `path`, and an existing file there stays intact
/// on failure. Returns the number of bytes written. Throws clod::Error: kInvalidArgument (as
/// encodeBake), kFileWriteFailed naming the path.
std::size_t saveBake(const std::filesystem::path& path, const BakeContents& contents);

/// Reads a bake file's header and section table and checks them (checkBakeFileStart) before it
/// reads the rest with a single read() (so a large file that is not a bake is refused after
/// 48 bytes), then decodes it (decodeBake).
/// Throws clod::Error: kFileNotFound, kFileUnreadable, kEmptyFile (zero bytes), and every
/// error of decodeBake; messages start with the path.
BakeContents loadBake(const std::filesystem::path& path);

/// What bakeMesh builds and how.
struct BakeSettings {
  SphereTreeSettings sphereTree;
  MeshDistanceSettings distance;
  /// Measure the fit of every sphere-tree level (measureSphereTreeFit) for the report.
  bool measureFit = true;
  /// Stored in BakeContents::sourceName.
  std::string sourceName;
  /// Build the closest feature maps (BakeContents::closestFeatureMap) with these settings.
  bool buildClosestFeatureMap = true;
  ClosestFeatureMapSettings closestFeatureMap;
  /// Build the contact tree (BakeContents::contactTree) with these settings (errorRel is
  /// relative to the mesh's bounding-box diagonal). Usually the slowest stage; its cost grows
  /// roughly with the surface area over errorRel (docs/contact-tree.md).
  bool buildContactTree = true;
  ContactTreeSettings contactTree;
  /// Memory a bake may use (0: no limit). bakeMesh refuses a mesh whose triangles alone would
  /// need more (kBakeBytesPerTriangle each: distance BVH, sphere-tree, maps) before it builds
  /// anything, and gives the contact tree what is left as ContactTreeSettings::maxNodes (a
  /// smaller maxNodes given there is kept). Both throw Error(kResourceLimit) naming the limit.
  std::uint64_t maxMemoryBytes = std::uint64_t{4} << 30;
};

/// Peak bytes per triangle of bakeMesh's stages before the contact tree (MeshDistance, the
/// sphere-tree, the closest feature maps), with margin: measured 1.2 kB on the 69k-triangle
/// Stanford bunny (132 MB peak without the contact tree, 47 MB of it the loaded mesh).
inline constexpr std::uint64_t kBakeBytesPerTriangle = 1536;
/// Peak bytes per contact-tree node while building (measured ~175, docs/bake-format.md).
inline constexpr std::uint64_t kBakeBytesPerContactTreeNode = 192;

/// Wall-clock seconds per stage of bakeMesh.
struct BakeTimings {
  double distanceSeconds = 0.0;    ///< building MeshDistance (BVH, topology, pseudonormals)
  double sphereTreeSeconds = 0.0;  ///< buildSphereTree
  double fitSeconds = 0.0;         ///< measureSphereTreeFit (0 if not measured)
  double cfmSeconds = 0.0;         ///< buildClosestFeatureMap (0 if not built)
  double contactTreeSeconds = 0.0; ///< buildContactTree (0 if not built)
  /// Everything that goes into the file: distanceSeconds + sphereTreeSeconds + cfmSeconds +
  /// contactTreeSeconds;
  /// excludes fit measurement.
  double buildSeconds = 0.0;
};

/// The result of bakeMesh: the contents to save plus a report on how they were built.
struct BakeResult {
  BakeContents contents;
  /// Fit per sphere-tree level, root first (empty unless BakeSettings::measureFit).
  std::vector<SphereTreeLevelFit> levelFit;
  /// How MeshDistance decided inside/outside for this mesh.
  SignMethod signMethod = SignMethod::kPseudonormal;
  BakeTimings timings;
  /// What the contact-tree builder did (all zero unless BakeSettings::buildContactTree).
  ContactTreeBuildStats contactTreeStats;
};

/// Builds everything a bake holds for `mesh`: MeshDistance, then the sphere-tree (put on the
/// file's grid at once, so what is built on it equals what a load returns), the closest
/// feature maps and the contact tree (each of the last two unless switched off in settings). The mesh must be valid (see MeshDistance). Throws clod::Error from the
/// builders: kInvalidArgument for out-of-range settings, mesh errors for invalid meshes.
/// Uses TBB inside the builders.
BakeResult bakeMesh(const TriangleMesh& mesh, const BakeSettings& settings);

}  // namespace clod
