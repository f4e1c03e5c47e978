// The nut-on-bolt scene (scenes/nut_bolt.json, thread_meshes.h) in clod's World: the M16 x 2
// nut, started on the bolt's first thread spinning down the helix, keeps screwing down under
// gravity (frictionless threads: gravity's pull along the flanks turns it) without jamming or
// passing through. Oracles, all independent of the narrow phase: the pitch (2 mm, ISO 68-1), the
// helix the nut must follow (its height against its turn), the thread's axial and radial play
// from the generator's clearance, and exact signed distances between the meshes at the poses
// the world reached (proximity.h). docs/engines.md, "Nut on a bolt", has the numbers.
//
// Cost: the exact model on ~3,600 triangles in tight contact takes ~5 ms per substep query
// (2-3 substeps per step), so 0.35 s simulated is ~3 s in Release on one core. Under the
// sanitizers (3-10x slower) the test is skipped with a message.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <numbers>

#include <gtest/gtest.h>

#include "clod/mesh_io.h"
#include "clod/proximity.h"
#include "clod/scene.h"
#include "clod/thread_meshes.h"
#include "clod/world.h"
#include "support/test_scale.h"

namespace clod {
namespace {

std::filesystem::path scenesDir() { return std::filesystem::path(CLOD_SCENES_DIR); }

// Deepest penetration of any vertex of `mesh` (placed by xf) into the solid `other`: max of
// -signedDistance over the vertices, 0 when none is inside. Vertices only: facets of one part
// can cross the other's edges without a vertex inside, but that overlap is bounded by the facet
// size times the angle, far below the tolerances here (chords of 2 mm at 7.5 degrees).
double vertexPenetration(const TriangleMesh& mesh, const Pose& xf, const MeshDistance& other) {
  double deepest = 0.0;
  for (const Vec3& v : mesh.vertices) deepest = std::max(deepest, -other.signedDistance(xf.apply(v)));
  return deepest;
}

TEST(NutBoltScene, NutScrewsDownOnePitchPerTurnWithoutJammingOrPassingThrough) {
  if (test::sanitizerRun()) GTEST_SKIP() << "Release only: ~4 s of exact queries in Release, minutes under the sanitizers";
  SceneDescription scene = loadScene(scenesDir() / "nut_bolt.json");
  ASSERT_EQ(scene.bodies.size(), 2u);
  ASSERT_EQ(scene.bodies[1].name, "nut");
  const NutBoltParts parts{};  // what `clod generate nut-bolt` wrote into scenes/nut_bolt/
  const double pitch = parts.thread.pitch;
  // The thread's play: a radial clearance c moves each 60-degree flank c tan 30 deg axially, so
  // the nut, started centred (z = 9 pitches, unturned), may sit that much either side of the
  // helix; radially it may shift by c.
  const double axialPlay = parts.radialClearance * std::tan(std::numbers::pi / 6);  // 86.6 um
  const double z0 = scene.bodies[1].position.z();
  ASSERT_NEAR(z0 / pitch, std::round(z0 / pitch), 1e-9);  // a whole number of pitches: centred in the play
  const std::uint32_t steps = 350;  // 0.35 s
  World world = buildWorld(scene, {});
  const MeshDistance bolt(loadMesh(scenesDir() / "nut_bolt" / "bolt.obj").mesh);
  const MeshDistance nut(loadMesh(scenesDir() / "nut_bolt" / "nut.obj").mesh);

  double unwrapped = 0.0, previous = 0.0;
  double helixLow = 0.0, helixHigh = 0.0, lateral = 0.0, tilt = 0.0, penetration = 0.0;
  double turnsAt50 = 0.0, zAt50 = 0.0;
  for (std::uint32_t s = 1; s <= steps; ++s) {
    world.step(scene.dt);
    const RigidBodyState st = world.state(1);
    // Turn about the bolt's axis (z), unwrapped; the nut's tilt away from it.
    const double angle = 2.0 * std::atan2(st.orientation.z(), st.orientation.w());
    double delta = angle - previous;
    delta -= 2.0 * std::numbers::pi * std::round(delta / (2.0 * std::numbers::pi));
    unwrapped += delta;
    previous = angle;
    const double turns = unwrapped / (2.0 * std::numbers::pi);
    // A right-hand thread: turning by t turns moves the nut by t pitches along z.
    const double offHelix = (st.position.z() - z0) - pitch * turns;
    helixLow = std::min(helixLow, offHelix);
    helixHigh = std::max(helixHigh, offHelix);
    lateral = std::max(lateral, std::hypot(st.position.x(), st.position.y()));
    tilt = std::max(tilt, std::acos(std::clamp((st.orientation * Vec3::UnitZ()).z(), -1.0, 1.0)));
    if (s == 50) turnsAt50 = turns, zAt50 = st.position.z();
    if (s % 25 == 0) {
      const Pose xfNut{st.orientation, st.position};
      penetration = std::max({penetration, vertexPenetration(nut.mesh(), xfNut, bolt),
                              vertexPenetration(bolt.mesh(), xfNut.inverse(), nut)});
    }
  }
  const RigidBodyState end = world.state(1);
  const double turns = unwrapped / (2.0 * std::numbers::pi);
  // Screwing down is a negative (clockwise from above) turn. At least one full turn in 0.35 s:
  // started at 20 rad/s (3.2 turns/s), frictionless, so only a jam stops it.
  EXPECT_LT(turns, -1.0);
  EXPECT_LT(end.angularVelocity.z(), -10.0) << "the nut slowed down: jamming";
  // Advance per turn after the first 50 steps (by then the nut has settled onto the load flank,
  // a one-off drop of up to the axial play): the pitch within 5 % (the bound).
  const double advancePerTurn = (end.position.z() - zAt50) / (turns - turnsAt50);
  EXPECT_NEAR(advancePerTurn, pitch, 0.05 * pitch);
  // Never off the helix by more than the play plus 10 um (1/200 of the pitch; the world allows
  // slopRel x diagonal = 78 um of penetration along the contact normal, which on a flank shows
  // as less than that axially because the nut rides on several flanks at once).
  EXPECT_GT(helixLow, -axialPlay - 10e-6);
  EXPECT_LT(helixHigh, axialPlay + 10e-6);
  EXPECT_LT(lateral, parts.radialClearance);
  EXPECT_LT(tilt, 1.0 * std::numbers::pi / 180.0);
  // Measured penetration of the actual meshes: less than 30 um, 1.5 % of the pitch (what the
  // world's slop lets through, see above).
  EXPECT_LT(penetration, 30e-6);
  std::printf("turns %.3f, advance per turn %.4f mm, helix offset [%.1f, %.1f] um, lateral %.1f um, tilt %.3f deg, "
              "vertex penetration %.1f um\n",
              turns, advancePerTurn * 1e3, helixLow * 1e6, helixHigh * 1e6, lateral * 1e6, tilt * 180 / std::numbers::pi,
              penetration * 1e6);
}

// The scene's meshes are what `clod generate nut-bolt` writes (byte for byte).
TEST(NutBoltScene, CommittedMeshesAreTheGeneratorsOutput) {
  for (const NamedMesh& part : nutBoltMeshes()) {
    std::ifstream in(scenesDir() / "nut_bolt" / (part.name + ".obj"), std::ios::binary);
    ASSERT_TRUE(in) << part.name;
    std::ostringstream text;
    text << in.rdbuf();
    EXPECT_EQ(text.str(), encodeObj(part.mesh, "clod generate nut-bolt: " + part.name + " (metres)"))
        << part.name << ".obj differs: run clod generate nut-bolt -o scenes/nut_bolt";
  }
}

}  // namespace
}  // namespace clod
