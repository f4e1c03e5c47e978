#pragma once
// Binary glTF 2.0 (.glb) export of rigid bodies and their motion, so a simulation plays in any
// glTF viewer or DCC tool and in clod's web viewer. The file layout the viewer relies on is the
// output-folder contract of docs/viewer-format.md; this header is its C++ side.
//
// What encodeGlb writes (glTF 2.0 specification, Khronos, 2021):
//   * one node per GltfBody, in order, named GltfBody::name, with node extras
//     {"body": <index>, "static": <bool>} and the initial pose as translation + rotation
//     (rotation in glTF order x, y, z, w);
//   * per distinct mesh (bodies that share a TriangleMesh object share one glTF mesh) one
//     triangle primitive with POSITION and NORMAL (float VEC3) and 32-bit indices, in the body's
//     own (mesh) frame. Normals are per vertex: angle-weighted averages of the face normals of
//     the triangles around a vertex, where a vertex is split when its triangles' normals differ
//     by more than kGltfCreaseAngle, so a box stays flat-shaded and a scanned bunny smooth. The
//     triangles keep their order and corner order (counter-clockwise = front face, as in
//     mesh.h), so triangle t of the primitive is triangle t of the mesh;
//   * when GltfScene::keyTimes is not empty, one animation named "simulation" with, for every
//     non-static body, a "translation" (VEC3) and a "rotation" (VEC4, x y z w) channel, LINEAR,
//     sharing one keyframe-time accessor (seconds).
// Units are the caller's (metres in clod scenes); axes are written as given (+Z up in clod
// scenes; no axis conversion, the viewer turns its camera instead).
//
// Validity guarantees (what the tests check): asset.version "2.0"; one buffer in the GLB BIN
// chunk; every buffer view starts at a multiple of 4 bytes; POSITION accessors and the
// keyframe-time accessor carry min/max; quaternions are unit length (normalised in float) and
// each body's keyframe quaternions are sign-continuous (q and -q are the same rotation; the
// sign nearest the previous key is written so LINEAR interpolation takes the short way);
// keyframe times strictly increasing.
//
// Writing goes through TinyGLTF (Debian's libtinygltf), which frames the GLB chunks.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "clod/math.h"
#include "clod/mesh.h"

namespace clod {

/// Vertices whose adjacent face normals differ by more than this (radians, 40 degrees) get
/// separate normals (a hard edge); below it they are smoothed.
inline constexpr double kGltfCreaseAngle = 0.6981317007977318;

/// One body of the exported scene.
struct GltfBody {
  std::string name;                   ///< node name (any UTF-8; may be empty)
  const TriangleMesh* mesh = nullptr; ///< non-null, >= 1 triangle; must outlive encodeGlb
  bool isStatic = false;              ///< static bodies get no animation channels
  Pose initialPose;                   ///< node TRS: where the mesh origin is, mesh -> world rotation
  /// One pose per GltfScene::keyTimes entry for a non-static body when keyTimes is not empty;
  /// ignored (may be empty) for static bodies.
  std::vector<Pose> keyframes;
};

/// Everything encodeGlb needs.
struct GltfScene {
  std::vector<GltfBody> bodies;  ///< >= 1 body
  /// Keyframe times in seconds, finite and strictly increasing; empty = no animation.
  std::vector<double> keyTimes;
};

/// Encodes the scene as a complete .glb file (the bytes, in a std::string so it goes straight
/// to writeFileAtomically). Deterministic: equal scenes give identical bytes.
/// Throws clod::Error(kInvalidArgument) naming the body or key: no bodies, a null mesh or one
/// without triangles, a non-finite vertex or pose, a vertex index out of range, keyTimes not
/// finite or not strictly increasing, a non-static body whose keyframe count differs from
/// keyTimes.size(), or more than 2^32-1 of anything.
/// O(total triangles x valence + bodies x keyframes); one output buffer, no per-vertex allocation.
std::string encodeGlb(const GltfScene& scene);

/// encodeGlb, then writeFileAtomically(path, ...): never leaves a partial file at `path`.
/// Throws what encodeGlb throws, and kFileWriteFailed naming the path.
void saveGlb(const std::filesystem::path& path, const GltfScene& scene);

}  // namespace clod
