#pragma once
// Closed triangle meshes of a threaded rod (a bolt's shank) and a hex nut with the ISO metric
// thread, for the nut-on-bolt scene (docs/engines.md, scenes/nut_bolt.json,
// scenes/mujoco/nut_bolt.xml; `clod generate nut-bolt -o DIR`).
//
// Thread profile: the ISO 68-1 basic profile. The fundamental triangle has flanks at 60 degrees
// (30 degrees either side of the radial plane) and height H = (sqrt(3) / 2) P for pitch P; it
// is truncated flat at the major diameter d (crest flat P / 8 wide) and at the basic minor
// diameter D1 = d - (5 / 4) H x 2 = d - 1.0825 P (root flat P / 4 wide), so the flanks span
// (5 / 8) H radially and 5 P / 16 axially. Both parts use this basic profile (the bolt's root is
// not rounded or deepened); the nut's is the bolt's grown radially by a clearance, so the two
// fit with that radial play at crest and root and clearance x tan 30 degrees of axial play on
// each flank.
//
// Shape: both parts are helical. Seen along the axis (z), a profile row -- a crest edge, a root
// edge -- is a helix z = z0 + P theta / (2 pi) (right-handed: it rises turning counter-clockwise
// seen from +z), sampled at `segmentsPerTurn` angles theta = 2 pi m / segmentsPerTurn, the
// first on +x. Between rows the surface is a strip of quads (two triangles each) whose edges
// follow the helix, so every vertex lies exactly on the true thread surface. The ends are not
// planar: each is one turn of a helicoidal ramp (the surface swept by a radial segment moving
// up the helix), closed by a flat step face in the half-plane y = 0, x > 0, where the ramp
// rises by one pitch. So at every angle the part is exactly `turns` pitches long: the volume
// and the mass properties come out in closed form (tests/mesh/thread_meshes_test.cpp), and a
// nut placed at z = k P (k integer, no rotation) sits centred in the bolt's thread.
//
// Conventions as primitives.h: counter-clockwise seen from outside, closed, manifold, one
// component, no degenerate triangles. Units are the caller's (metres in the scenes). Invalid
// parameters (non-finite or non-positive sizes, counts out of range, a nut whose hex does not
// enclose its thread) throw clod::Error(kInvalidArgument) naming the parameter.

#include <cstdint>
#include <vector>

#include "clod/mesh.h"
#include "clod/part_meshes.h"

namespace clod {

/// An ISO metric thread: major (nominal) diameter and pitch, e.g. M16 x 2: {0.016, 0.002}.
struct IsoThread {
  double majorDiameter = 0.016;
  double pitch = 0.002;

  /// Height of the fundamental triangle, H = (sqrt(3) / 2) pitch (= 0.866 P).
  double fundamentalHeight() const;
  /// Basic minor diameter D1 = majorDiameter - (5 / 4) H x 2 (the root flat of the basic profile).
  double minorDiameter() const;
  /// Basic pitch diameter d2 = majorDiameter - (3 / 4) H x 2 (flank width = groove width).
  double pitchDiameter() const;
  /// Radius of the basic profile at axial phase u in [0, pitch) along a row of constant angle,
  /// phase 0 at the start of the root flat: root flat (minor radius) on [0, P/4), rising flank
  /// on [P/4, 9P/16), crest flat (major radius) on [9P/16, 11P/16), falling flank on
  /// [11P/16, P). The bolt's surface at (theta, z) has radius profileRadius(z - P theta / 2 pi
  /// mod P); the nut's, that plus its clearance.
  double profileRadius(double phase) const;
  /// pi x the integral of profileRadius(u)^2 over one pitch: the volume per pitch of a solid
  /// bounded by the (smooth) thread, the same for the helical thread as for rings of that
  /// profile (Cavalieri: every half-plane through the axis cuts the same profile, shifted).
  double solidVolumePerPitch(double radialOffset = 0.0) const;
};

/// Throws kInvalidArgument naming the value unless both are finite and positive and the pitch
/// leaves a positive minor diameter.
void validateIsoThread(const IsoThread& thread);

/// A threaded rod: the external thread of `thread` with helicoidal ends (see the top), from
/// z = 0 (the bottom ramp starts at angle 0) to z = (turns + 1) pitch (where the top ramp ends),
/// exactly `turns` pitches long at every angle. turns in [1, 4096], segmentsPerTurn in [6, 4096].
/// n = segmentsPerTurn: (4 turns + 1) n + 4 vertices on the thread plus 2 (n + 1) on the axis;
/// 8 turns n triangles on the thread, 2 n on each ramp and n + 4 on each step face.
/// Volume of the smooth part: turns x solidVolumePerPitch(); the mesh's vertices lie on that
/// surface and its facets inside it (a polygon of segmentsPerTurn sides instead of a circle).
/// O(triangles).
TriangleMesh makeThreadedRod(const IsoThread& thread, std::uint32_t turns, std::uint32_t segmentsPerTurn);

/// A hex nut with the internal thread of `thread` grown radially by `radialClearance` (>= 0),
/// from z = 0 to z = (turns + 1) pitch with helicoidal ends like makeThreadedRod (so it fits a
/// rod's thread when placed at z = k pitch, unturned), outside a regular hexagonal prism
/// `acrossFlats` wide with corners at angles 0, 60, ... degrees. segmentsPerTurn must be a
/// multiple of 6 (the corners are then sample angles and every side quad is flat), in
/// [6, 4096]; acrossFlats / 2 must exceed the thread's major radius + clearance. n =
/// segmentsPerTurn: (4 turns + 1) n + 4 thread vertices and (turns + 1) n + 1 on the hexagon;
/// 8 turns n + 2 turns n triangles on the two walls, 2 n on each ramp, 5 on each step. Volume of the
/// smooth part: turns x (pitch x hexagon area - solidVolumePerPitch(radialClearance)).
/// O(triangles).
TriangleMesh makeHexNut(const IsoThread& thread, double radialClearance, double acrossFlats, std::uint32_t turns,
                        std::uint32_t segmentsPerTurn);

/// The parts of the nut-on-bolt scene, M16 x 2 (metres):
///   bolt  threaded rod, 10 turns (z 0 .. 22 mm), 24 segments per turn
///   nut   hex nut 24 mm across flats, 6 turns (14 mm tall), radial clearance 0.15 mm,
///         24 segments per turn
/// `clod generate nut-bolt -o DIR` writes them as DIR/bolt.obj and DIR/nut.obj.
struct NutBoltParts {
  IsoThread thread;
  double radialClearance = 0.00015;
  double acrossFlats = 0.024;
  std::uint32_t boltTurns = 10;
  std::uint32_t nutTurns = 6;
  std::uint32_t segmentsPerTurn = 24;
};
std::vector<NamedMesh> nutBoltMeshes(const NutBoltParts& parts = {});

}  // namespace clod
