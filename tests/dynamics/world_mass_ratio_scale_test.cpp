// Physics across mass ratios and sizes (issue 21, point 3), against analytic rest positions and
// sliding distances: a heavy box on a light one on the ground (and the other way round) stands at
// ratios up to 1,000 : 1, and resting boxes, a 3-box stack and a sliding box behave alike from
// 1 mm to 100 m, with every contact model at a small, a middle and an unlimited budget.
// Thresholds are relative to the box size; each is justified where it is used.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "clod/bake.h"
#include "clod/collision_body.h"
#include "clod/contact_tree_builder.h"
#include "clod/mass_properties.h"
#include "clod/mesh_io.h"
#include "clod/primitives.h"
#include "clod/proximity.h"
#include "clod/world.h"
#include "support/test_paths.h"
#include "support/test_scale.h"
#include "world_test_support.h"

namespace clod {
namespace {

using test::sanitizerRun;

std::shared_ptr<const CollisionBody> bakeShape(const TriangleMesh& mesh) { return test::bakeWorldShape(mesh); }

// A unit cube (side 1) and a slab of 4 x 4 x 0.5 cube sides; World::addBody(desc, scale) makes
// every size from them, so each size runs the same geometry in other units.
const std::shared_ptr<const CollisionBody>& unitCube() { return test::unitWorldCube(); }
const std::shared_ptr<const CollisionBody>& unitSlab() {
  static const auto shape = bakeShape(makeBox(Vec3(4.0, 2.0, 0.25)));
  return shape;
}

// A solid cube of side `side` and mass `mass` at `centre` (mesh origin = centre of mass).
RigidBodyDesc cubeAt(double side, double mass, const Vec3& centre) {
  RigidBodyDesc d;
  d.shape = unitCube();
  d.mass = mass;
  d.inertia = Mat3::Identity() * (mass * side * side / 6.0);  // m (a^2 + a^2) / 12
  d.position = centre;
  d.friction = 0.6;
  return d;
}

// The slab scaled to `side`, top face at z = 0.
World groundWorld(ContactModel model, std::uint64_t budget, double side) {
  WorldSettings ws;
  ws.model = model;
  ws.budgetTests = budget;
  ws.bounds = Aabb{Vec3::Constant(-1e3 * side), Vec3::Constant(1e3 * side)};
  World world(ws);
  RigidBodyDesc ground;
  ground.shape = unitSlab();
  ground.type = BodyType::kStatic;
  ground.position = Vec3(0.0, 0.0, -0.25 * side);
  ground.friction = 0.6;
  world.addBody(ground, side);
  return world;
}

using test::tiltDegrees;

const std::vector<ContactModel>& models() {
  static const std::vector<ContactModel> all{ContactModel::kCfm, ContactModel::kExact, ContactModel::kContactTree};
  return all;
}
std::vector<std::uint64_t> budgets() {
  // Under the sanitizers the smallest and the unlimited budget: the middle one takes the same
  // code paths (an interrupted and a finished query).
  if (sanitizerRun()) return {16, 0};
  return {16, 256, 0};
}

// Box i of a stack of unit cubes on the ground at rest has its centre at z = i + 0.5 (analytic).
// What a stack did over `steps` steps at 60 Hz, in box sides, checked every step (a box that
// sinks and comes back up counts): the deepest any box got below that height, the farthest any
// got beside its start, and the farthest any got in the last second from where it then was.
struct StackMotion {
  double lowest = 0.0, farthest = 0.0, lastSecond = 0.0;
};
StackMotion stepStack(World& world, const std::vector<BodyId>& ids, double side, int steps) {
  StackMotion m;
  std::vector<Vec3> oneSecondAgo(ids.size());
  const int lastSecondStart = std::max(0, steps - 60);
  for (int s = 0; s < steps; ++s) {
    if (s == lastSecondStart)
      for (std::size_t i = 0; i < ids.size(); ++i) oneSecondAgo[i] = world.state(ids[i]).position / side;
    world.step(1.0 / 60.0);
    for (std::size_t i = 0; i < ids.size(); ++i) {
      const Vec3 p = world.state(ids[i]).position / side;
      m.lowest = std::max(m.lowest, (double(i) + 0.5) - p.z());
      m.farthest = std::max(m.farthest, std::hypot(p.x(), p.y()));
      if (s >= lastSecondStart) m.lastSecond = std::max(m.lastSecond, (p - oneSecondAgo[i]).norm());
    }
  }
  return m;
}

// No box lower than 1 % of its side below its height (issue 21's criterion), none more than 1 %
// beside its start (a squeezed-out box moves sideways by its whole size), and at the end at rest
// and upright.
void expectStackStands(World& world, const std::vector<BodyId>& ids, double side, int steps, const std::string& what) {
  const StackMotion m = stepStack(world, ids, side, steps);
  // Each contact may rest up to the slop inside (0.2 % of the smaller diagonal, 0.35 % of a side,
  // WorldSettings::slopRel), so the box on top of n contacts n times that; 1 % per box holds it.
  EXPECT_LT(m.lowest, 0.01 * double(ids.size())) << what << ": a box sank";
  EXPECT_LT(m.farthest, 0.01) << what << ": a box moved sideways";
  for (BodyId id : ids) {
    const RigidBodyState s = world.state(id);
    // At rest: slower than 1 % of a side per second (a box falling its own size reaches
    // sqrt(2 g side), 4.4 sides per second at 1 m).
    EXPECT_LT(s.velocity.norm() / side, 0.01) << what;
    EXPECT_LT(tiltDegrees(s.orientation), 1.0) << what;
  }
}

// A 1,000 kg box on a 1 kg box on the ground squeezed the light box out sideways (cfm, exact) or
// pushed it through the ground (contact tree): projected Gauss-Seidel passes the heavy box's
// weight down to the ground at a rate of M / (M + m) per iteration. Fixed by shock propagation
// (docs/dynamics.md, "Mass ratios"); this fails without it at 100 : 1 and 1,000 : 1.
TEST(WorldMassRatio, HeavyOnLightAndLightOnHeavyStacksStandWithEveryModelAndBudget) {
  for (double ratio : {10.0, 100.0, 1000.0})
    for (bool heavyOnTop : {true, false})
      for (ContactModel model : models())
        for (std::uint64_t budget : budgets()) {
          if (sanitizerRun() && ratio != 1000.0) continue;
          World world = groundWorld(model, budget, 1.0);
          const double lower = heavyOnTop ? 1.0 : ratio, upper = heavyOnTop ? ratio : 1.0;
          std::vector<BodyId> ids{world.addBody(cubeAt(1.0, lower, Vec3(0, 0, 0.5))),
                                  world.addBody(cubeAt(1.0, upper, Vec3(0, 0, 1.5)))};
          const std::string what = std::string(contactModelName(model)) + " budget " + std::to_string(budget) +
                                   (heavyOnTop ? " heavy on top, " : " light on top, ") + std::to_string(int(ratio)) + ":1";
          expectStackStands(world, ids, 1.0, 180, what);  // 3 s
        }
}

// The same stack dropped: the light box from 5 % of its side onto the ground, a box `ratio` times
// heavier from 10 % onto it; cubes of side `side` (the masses scale with the volume). Both land
// flat and aligned, so by symmetry nothing pushes either sideways (oracle: the start's x, y).
void expectHeavyBoxStaysOnLightOne(ContactModel model, std::uint64_t budget, double ratio, double side = 1.0,
                                   double sideways = 0.01) {
  const std::string what = std::string(contactModelName(model)) + " budget " + std::to_string(budget) + " " +
                           std::to_string(int(ratio)) + ":1, side " + std::to_string(side);
  World world = groundWorld(model, budget, side);
  const double mass = side * side * side;
  const std::vector<BodyId> ids{world.addBody(cubeAt(side, mass, Vec3(0, 0, 0.55 * side)), side),
                                world.addBody(cubeAt(side, ratio * mass, Vec3(0, 0, 1.6 * side)), side)};
  const StackMotion m = stepStack(world, ids, side, 180);  // 3 s
  // The criteria of expectStackStands, except "at rest": at 1,000 : 1 the iterations leave
  // the pinched pair a velocity residual that changes sign from step to step, a jitter about a
  // fixed pose (docs/dynamics.md, "Known limits"). So rest is the farthest either box got in the
  // last second from where it was at its start: under 0.5 % of a side (the creep below moved
  // 6 cm in a second), and issue 17's resting-stack speed bound (5 cm/s) on the velocity.
  EXPECT_LT(m.lowest, 0.02) << what << ": a box sank";
  EXPECT_LT(m.farthest, sideways) << what << ": a box moved sideways";
  EXPECT_LT(m.lastSecond, 0.005) << what << ": moved in the last second";
  for (BodyId id : ids) {
    // Speeds scale with sqrt(side) (Froude similarity, below).
    EXPECT_LT(world.state(id).velocity.norm(), 0.05 * std::sqrt(side)) << what;
    EXPECT_LT(tiltDegrees(world.state(id).orientation), 1.0) << what;
  }
}

// The landing tilts the boxes by ~0.04 deg, and the heavy box's normal impulse, 1,000 times the
// light box's weight, then has a tangential part the ground's static friction cancels;
// integrating that friction by the trapezoid rule as if it were a smooth force moved the light
// box 1 mm per step, 18 cm in 3 s (docs/dynamics.md, "Integration").
TEST(WorldMassRatio, HeavyBoxDroppedOnALightOneStaysOnItWithEveryModel) {
  for (ContactModel model : models())
    for (std::uint64_t budget : budgets()) expectHeavyBoxStaysOnLightOne(model, budget, 1000.0);
}

// The sphere models (dos, average) at limited budgets: their interrupted contacts between the
// two boxes carry the big spheres' centre lines or mean normals, tilted up to 45 deg, and the
// heavy box's weight along them pushed it off the light one (dos, 0.77 m at 100 : 1 and 16 tests
// per frame in a scene file's world) or through it and the ground (average). They now take the
// supporting body's box direction (docs/dynamics.md, "Sphere models' interrupted contacts"); here
// dos at 64 tests and 100 : 1 moved the boxes 1.1 % of a side without it. At 16 tests per frame
// the light box hops a fraction of a millimetre as the heavy one lands; its ground pair, forgotten
// for that substep, came back at its roots, which its 4-8 tests per substep could not expand
// (1 + 8 tests), and the one D&O contact under the light box's centre let the heavy box tip off
// (1.07 m at 100 : 1, both models); pairs now keep their caches while their boxes are near
// (docs/dynamics.md, "Pairs and their caches"). At 1 cm and 1 mm a frame has ~20 substeps, and
// 16 tests per frame gave the ground pair at most an even share of 8 tests in the last one:
// never the 1 + 8 of its roots' expansion, so it kept one D&O contact under the light box's
// centre, and the boxes tipped and fell through the ground. A sphere-model pair may now take
// what one expansion of its front needs (docs/dynamics.md, "Collision budget per frame").
TEST(WorldMassRatio, SphereModelsKeepAHeavyBoxOnALightOneAtLimitedBudgets) {
  for (ContactModel model : {ContactModel::kDos, ContactModel::kAverage}) {
    for (std::uint64_t budget : {16, 64, 256, 1024}) {
      // Sideways: at 16 tests the heavy box lands on the light one's level-1 spheres, whose few
      // D&O points are not symmetric about the boxes' axis: up to 1.02 % of a side (0.18 % before
      // a pair could borrow tests from the step's later substeps, for its ground pair, but then
      // a bunny dropped at 16 tests turned 140 deg). 2 % is issue 17's bound for a resting
      // stack of 1 m boxes (2 cm); a squeezed-out box moves its whole side.
      const double sideways = budget == 16 ? 0.02 : 0.01;
      expectHeavyBoxStaysOnLightOne(model, budget, 100.0, 1.0, sideways);
      expectHeavyBoxStaysOnLightOne(model, budget, 1000.0, 1.0, sideways);
    }
    for (double side : {0.001, 0.01}) expectHeavyBoxStaysOnLightOne(model, 16, 1000.0, side);
  }
}

// A plate 1,000 times denser than the box under it, standing on its thin edge (0.12 of its 0.58
// length, 0.45 high) turned 60 deg about the vertical, sides `side` times these (a random probe's
// `mass` scene, seed 1429). At 16 tests per frame the sphere models' pair of the two boxes has
// its roots' one D&O contact under the plate's middle for many substeps: a carried-on
// interrupted answer between two moving bodies was not held at their boxes, and the plate
// turned off that contact onto its side (90 deg at 1 mm, dos and average). Held, it rocked on
// that contact while its patch friction acted at its base, moved down to the holds, and stood
// 1.1 deg tilted (docs/dynamics.md, "Patch friction"). Oracle: standing still, the plate
// neither tilts nor moves.
void expectThinPlateStandsOnALightBox(ContactModel model, double side) {
  const std::string what = std::string(contactModelName(model)) + " side " + std::to_string(side);
  World world = groundWorld(model, 16, side);
  static const auto lightShape = bakeShape(makeBox(Vec3(0.344, 0.217, 0.238)));
  static const auto plateShape = bakeShape(makeBox(Vec3(0.291, 0.060, 0.224)));
  auto box = [&](const std::shared_ptr<const CollisionBody>& shape, const Vec3& half, double density, double z) {
    RigidBodyDesc d;
    d.shape = shape;
    d.mass = density * 8.0 * (side * half).prod();  // the scaled body's (World::addBody)
    d.inertia = test::solidBoxInertia(side * half, d.mass);
    d.position = Vec3(0.0, 0.0, z);
    d.friction = 0.9;
    return d;
  };
  const BodyId light = world.addBody(box(lightShape, Vec3(0.344, 0.217, 0.238), 1.0, 0.238 * side), side);
  RigidBodyDesc plate = box(plateShape, Vec3(0.291, 0.060, 0.224), 1000.0, (2.0 * 0.238 + 0.224) * side);
  plate.orientation = Quat(Eigen::AngleAxisd(M_PI / 3.0, Vec3::UnitZ()));
  const BodyId heavy = world.addBody(plate, side);
  const Vec3 start = world.state(heavy).position;
  for (int s = 0; s < 60; ++s) world.step(1.0 / 60.0);  // 1 s: it fell over within 0.15 s
  // Tilt: issue 17's resting-stack bound (1 deg). Moved: 1 % of the side (a plate on its side has
  // moved 20 % of it); the light box under it is 0.48 of the side tall and rests within the slop.
  EXPECT_LT(tiltDegrees(world.state(heavy).orientation), 1.0) << what;
  EXPECT_LT((world.state(heavy).position - start).norm() / side, 0.01) << what;
  EXPECT_LT(tiltDegrees(world.state(light).orientation), 1.0) << what;
}

TEST(WorldMassRatio, SphereModelsKeepAThinPlateOnItsEdgeOnALightBoxAtSixteenTestsPerFrame) {
  for (ContactModel model : {ContactModel::kDos, ContactModel::kAverage})
    for (double side : {0.001, 1.0}) expectThinPlateStandsOnALightBox(model, side);
}

// The same box scenes from 1 mm to 100 m, each made from the unit shapes by World::addBody's
// scale. Under a uniform scale by s with g fixed, motions keep their shape when time scales by
// sqrt(s) (Froude similarity): speeds by sqrt(s), so a slide at 2 sqrt(s) m/s stops after
// v^2 / (2 mu g) = 0.408 s. Each scene runs 3 sqrt(max(s, 1)) simulated seconds (a 100 m box
// sliding at 20 m/s stops after 4.1 s).
void expectBoxScenesAlike(ContactModel model, std::uint64_t budget, double side) {
  const int steps = int(std::lround(180.0 * std::sqrt(std::max(side, 1.0))));
  const double mass = 1000.0 * side * side * side;  // water density
  const std::string what =
      std::string(contactModelName(model)) + " budget " + std::to_string(budget) + " side " + std::to_string(side);
  {  // a resting box
    World world = groundWorld(model, budget, side);
    expectStackStands(world, {world.addBody(cubeAt(side, mass, Vec3(0, 0, 0.5 * side)), side)}, side, steps,
                      what + " rest");
  }
  {  // a stack of three
    World world = groundWorld(model, budget, side);
    std::vector<BodyId> ids;
    for (int i = 0; i < 3; ++i) ids.push_back(world.addBody(cubeAt(side, mass, Vec3(0, 0, (i + 0.5) * side)), side));
    expectStackStands(world, ids, side, steps, what + " stack");
  }
  {  // a slide from 2 sqrt(side) m/s
    World world = groundWorld(model, budget, side);
    RigidBodyDesc box = cubeAt(side, mass, Vec3(-3.0 * side, 0, 0.5 * side));
    box.friction = 0.5;
    box.velocity = Vec3(2.0 * std::sqrt(side), 0, 0);
    // The ground's friction 0.6 mixes to sqrt(0.5 * 0.6); the analytic stop uses the mix.
    const double mu = std::sqrt(0.5 * 0.6);
    const BodyId id = world.addBody(box, side);
    double lowest = 0.0;
    for (int s = 0; s < steps; ++s) {
      world.step(1.0 / 60.0);
      lowest = std::max(lowest, 0.5 - world.state(id).position.z() / side);
    }
    const double expected = 4.0 * side / (2.0 * mu * 9.81);
    const RigidBodyState s = world.state(id);
    // Within 15 %: the slide lasts v / (mu g) = 0.37 sqrt(side) s, 12 ms at 1 mm -- about 6 of
    // the step's 8 substeps -- and semi-implicit Euler takes each substep's friction off
    // before it moves, which shortens a slide of n substeps by about 1 / (2 n), 9 % at 1 mm
    // (measured 10.2 %) and under 1 % from 1 m up.
    EXPECT_NEAR(s.position.x() + 3.0 * side, expected, 0.15 * expected) << what << " slide";
    EXPECT_LT(lowest, 0.01) << what << " slide: sank";
    EXPECT_LT(tiltDegrees(s.orientation), 1.0) << what << " slide";
    EXPECT_LT(s.velocity.norm() / side, 0.01) << what << " slide";
  }
}

TEST(WorldMassRatio, BoxScenesFromOneMillimetreToOneHundredMetresRestStackAndSlideAlike) {
  for (double side : {0.001, 0.01, 1.0, 10.0, 100.0})
    for (ContactModel model : models())
      for (std::uint64_t budget : {std::uint64_t(16), std::uint64_t(0)}) {
        if (sanitizerRun() && side != 0.001 && side != 100.0) continue;
        expectBoxScenesAlike(model, budget, side);
      }
}

// A 4-3-2-1 pyramid of cubes (each row resting on the one below, 3 % of a side between
// neighbours) at 16 tests per frame: its 26 broad-phase pairs outnumber a frame's tests, and
// at 1 mm a frame of free fall (2.7 mm at 60 Hz) is more than a box. Every box fell through the
// boxes under it and the ground before the budget reached its pairs, with every model; now a
// pair not yet reached is held at its boxes' gap (docs/dynamics.md, "Pairs the budget has not
// reached"). Oracle: the analytic rest heights, as expectStackStands.
TEST(WorldMassRatio, AMillimetrePyramidStandsWhileSixteenTestsPerFrameReachItsPairsInTurn) {
  for (double side : {0.001, 0.01})
    for (ContactModel model : models()) {
      if (sanitizerRun() && side != 0.001) continue;
      World world = groundWorld(model, 16, side);
      const double mass = 1000.0 * side * side * side;
      struct Placed {
        BodyId id;
        Vec3 start;  // in sides
      };
      std::vector<Placed> boxes;
      for (int row = 0; row < 4; ++row)
        for (int i = 0; i < 4 - row; ++i) {
          const Vec3 start((i - 0.5 * (3 - row)) * 1.03, 0.0, row + 0.5);
          boxes.push_back({world.addBody(cubeAt(side, mass, side * start), side), start});
        }
      const std::string what = std::string(contactModelName(model)) + " side " + std::to_string(side);
      double lowest = 0.0, farthest = 0.0;
      for (int s = 0; s < 60; ++s) {
        world.step(1.0 / 60.0);
        for (const Placed& b : boxes) {
          const Vec3 p = world.state(b.id).position / side;
          lowest = std::max(lowest, b.start.z() - p.z());
          farthest = std::max(farthest, std::hypot(p.x() - b.start.x(), p.y() - b.start.y()));
        }
      }
      // As expectStackStands: the slop per contact, 1 % per row (the top box rests on 4 rows).
      EXPECT_LT(lowest, 0.04) << what << ": a box sank";
      EXPECT_LT(farthest, 0.01) << what << ": a box moved sideways";
      for (const Placed& b : boxes) EXPECT_LT(world.state(b.id).velocity.norm() / side, 0.01) << what;
    }
}

// The sphere models too. At an unlimited budget their leaf spheres still bound the faces rather
// than follow them, so their contacts take the supporting body's face direction as the
// interrupted ones do (docs/dynamics.md): a box sliding at 2 sqrt(side) m/s failed to slide its
// distance or tilted 1.5-4 deg, at every size. At 16 tests per frame a pair borrows from the
// step's later substeps the tests one expansion of its front needs. At 1 mm and 16 tests a step
// has 128 substeps (the first-contact rule: gravity alone moves a 1 mm box 1.6 diagonals per
// 60 Hz frame), an eighth of a test each, and the slide's first frame runs on the roots' one D&O
// contact, which friction tipped 23 deg until such a pair was held at its hull boxes beside it
// (docs/dynamics.md, "Pairs the budget has not reached").
TEST(WorldMassRatio, SphereModelsRestStackAndSlideFromOneMillimetreToOneHundredMetres) {
  for (double side : {0.001, 0.01, 1.0, 10.0, 100.0})
    for (ContactModel model : {ContactModel::kDos, ContactModel::kAverage})
      for (std::uint64_t budget : {std::uint64_t(16), std::uint64_t(0)}) {
        if (sanitizerRun() && side != 0.001 && side != 100.0) continue;
        expectBoxScenesAlike(model, budget, side);
      }
}


// A box dropped onto the ground, landing on an edge (turned 45 deg about x) or on a corner (a
// space diagonal vertical): its lowest corner never more than 1 % of its diagonal below the
// ground's top at any frame (issue 17's criterion for drops), at 1 mm and 1 cm as at 1 m. Oracle:
// the eight corners' analytic heights. How deep a body arrives depends on where the last substep
// before contact ends, so each case drops from ten heights (0.1 ... 1 diagonal) and the deepest
// counts. At 60 Hz a 1 mm box falls more than its diagonal in the frame it lands in; with the
// approach substeps capped at 16 it arrived up to 11 % deep and ended that frame 4.2 % deep
// (1 cm: 0.89 %); kMaxFirstContactRel's substeps keep it at 0.34 % (docs/dynamics.md, "Substeps").
TEST(WorldMassRatio, SmallBoxesDroppedOnAnEdgeOrACornerNeverSinkPastOnePercent) {
  struct Landing {
    const char* name;
    Quat turn;
  };
  const Landing landings[] = {{"on an edge", Quat(Eigen::AngleAxisd(M_PI / 4.0, Vec3::UnitX()))},
                              // acos(1 / sqrt(3)) about (1, -1, 0)
                              {"on a corner", Quat(Eigen::AngleAxisd(0.9553, Vec3(1.0, -1.0, 0.0).normalized()))}};
  auto corner = [](int c) { return Vec3(c & 1 ? 0.5 : -0.5, c & 2 ? 0.5 : -0.5, c & 4 ? 0.5 : -0.5); };
  // Two whole convex polyhedra get the same separating-axis contacts in every model at every
  // budget (FlushContact tests), so one budget covers them.
  for (double side : {0.001, 0.01, 1.0})
    for (const auto& [name, turn] : landings)
      for (ContactModel model : models()) {
        if (sanitizerRun() && (side != 0.001 || model != ContactModel::kExact)) continue;
        const double diag = std::sqrt(3.0) * side;
        double below = 0.0;  // the lowest corner's depth below the centre, in sides
        for (int c = 0; c < 8; ++c) below = std::max(below, -(turn * corner(c)).z());
        double deepest = 0.0;
        for (int h = 1; h <= 10; ++h) {
          World world = groundWorld(model, 0, side);
          RigidBodyDesc box = cubeAt(side, 1000.0 * side * side * side, Vec3(0, 0, below * side + 0.1 * h * diag));
          box.orientation = turn;
          const BodyId id = world.addBody(box, side);
          for (int s = 0; s < 45; ++s) {  // 0.75 s: lands within 0.46 sqrt(side) s
            world.step(1.0 / 60.0);
            const RigidBodyState st = world.state(id);
            for (int c = 0; c < 8; ++c) deepest = std::max(deepest, -(st.position + side * (st.orientation * corner(c))).z() / diag);
          }
        }
        EXPECT_LT(deepest, 0.01) << contactModelName(model) << " side " << side << " " << name;
      }
}

// A turned bunny-1500 of 1.3 cm dropped on the ground at 16 tests per frame and 60 Hz (a drop of
// scripts/probe-random-scenes.py, seed 1402 at 1 cm): its lowest vertex never more than 1 % of
// its diagonal below the ground's top at any frame (issue 17's criterion for drops). Oracle: the
// mesh's vertices placed by the body's pose. Its fall takes ~50 substeps per frame and the budget
// answers the pair every third, from the roots; the skipped substeps hold the pair at the bodies'
// hull boxes (docs/dynamics.md, "Pairs the budget has not reached"). With the mesh box turned
// with the bunny, which reached 4 mm below its lowest vertex, the boxes overlapped on every axis
// before it landed, nothing held it, and it fell 2.6 % of its diagonal into the ground (cfm,
// exact, the contact tree); held without its pivot points while the roots' answer had one
// contact, it turned about that contact and sank 1.1 %. Ten heights, as above.
TEST(WorldMassRatio, ATurnedCentimetreBunnyDroppedAtSixteenTestsPerFrameNeverSinksPastOnePercent) {
  const TriangleMesh mesh = loadMesh(std::string(CLOD_SHARED_MESH_DIR) + "/bunny-1500.obj").mesh;
  static const auto shape = bakeShape(mesh);
  const double scale = 0.013 / shape->diagonal();
  const double diag = 0.013;
  const MassProperties unit = computeMassPropertiesOrBoundingBox(mesh, 1000.0);
  const Quat turn = Quat(0.9038871889888753, -0.3085577545052908, 0.2753540513993914, -0.10936273631536068).normalized();
  double below = 0.0;  // the lowest vertex's depth below the mesh origin
  for (const Vec3& v : mesh.vertices) below = std::max(below, -(turn * (scale * v)).z());
  for (ContactModel model : models()) {
    if (sanitizerRun() && model != ContactModel::kCfm) continue;
    double deepest = 0.0;
    for (int h = 1; h <= 10; ++h) {
      World world = groundWorld(model, 16, 0.05);
      RigidBodyDesc bunny;
      bunny.shape = shape;
      bunny.mass = unit.mass * scale * scale * scale;
      bunny.inertia = unit.inertia * std::pow(scale, 5.0);
      bunny.centerOfMass = scale * unit.centerOfMass;
      bunny.position = Vec3(0.0, 0.0, below + 0.1 * h * diag);
      bunny.orientation = turn;
      const BodyId id = world.addBody(bunny, scale);
      for (int s = 0; s < 30; ++s) {  // 0.5 s: lands within 0.1 s
        world.step(1.0 / 60.0);
        const RigidBodyState st = world.state(id);
        for (const Vec3& v : mesh.vertices)
          deepest = std::max(deepest, -(st.position + st.orientation * (scale * v)).z() / diag);
      }
    }
    EXPECT_LT(deepest, 0.01) << contactModelName(model);
  }
}

// A pile of six turned boxes of ~0.5 mm dropped onto the ground from up to 3.8 mm (a pile of
// scripts/probe-random-scenes.py, seed 1404 at 1 mm), at 16 tests per frame and 60 Hz: no corner
// of a box more than 1 % of its diagonal below the ground's top at any frame. Oracle: the boxes'
// analytic corners. The frame has ~100 substeps and the budget reaches each of the ~15 pairs every
// few. A box spinning at ~70 rad/s, its ground pair skipped without contacts, turned a corner
// through the hold, which acted at the middle of the boxes' overlap only; the boxes then overlapped
// by more than 1 %, the hold let go, and the box fell 42 % of its diagonal into the ground with
// every model. The hold now holds each moving body's hull point nearest the other box's face too
// (docs/dynamics.md, "Pairs the budget has not reached").
TEST(WorldMassRatio, ASpinningBoxOfAMillimetrePileIsHeldAboveTheGroundWhileItsPairWaits) {
  struct Box {
    Vec3 half, position;
    Quat turn;
  };
  const Box boxes[] = {
      {{1.5903e-4, 1.8646e-4, 1.7468e-4}, {1.6600e-4, 7.7288e-6, 3.2095e-4}, Quat(0.614685, -0.623250, 0.444151, 0.190925)},
      {{2.5397e-4, 2.6779e-4, 9.8252e-5}, {-1.8444e-4, 1.0589e-4, 1.02382e-3}, Quat(0.974993, -0.191574, 0.060591, -0.094958)},
      {{2.6985e-4, 2.7279e-4, 1.2523e-4}, {6.2016e-5, -1.9226e-4, 1.82938e-3}, Quat(0.938307, 0.334626, -0.087136, -0.003679)},
      {{2.1727e-4, 1.5156e-4, 6.4426e-5}, {2.0857e-5, 8.7203e-5, 2.52564e-3}, Quat(0.377543, 0.591717, 0.013365, -0.712147)},
      {{2.1742e-4, 1.2631e-4, 2.0478e-4}, {-1.5588e-5, -6.5575e-5, 3.14255e-3}, Quat(0.720930, -0.158214, -0.654669, -0.163208)},
      {{1.0911e-4, 2.0531e-4, 1.3073e-4}, {-1.5114e-4, -1.9327e-4, 3.75357e-3}, Quat(0.725582, 0.119453, -0.345876, -0.582780)}};
  std::vector<std::shared_ptr<const CollisionBody>> shapes;
  for (const Box& b : boxes) shapes.push_back(bakeShape(makeBox(b.half)));
  for (ContactModel model : models()) {
    if (sanitizerRun() && model != ContactModel::kCfm) continue;
    World world = groundWorld(model, 16, 0.01);  // 8 x 4 cm: wide enough for where the boxes scatter
    std::vector<BodyId> ids;
    for (std::size_t i = 0; i < shapes.size(); ++i) {
      const Vec3 size = 2.0 * boxes[i].half;
      RigidBodyDesc box;
      box.shape = shapes[i];
      box.mass = 1000.0 * size.prod();
      const Vec3 sq = size.cwiseProduct(size);
      box.inertia = (box.mass / 12.0) * Vec3(sq.y() + sq.z(), sq.x() + sq.z(), sq.x() + sq.y()).asDiagonal();
      box.position = boxes[i].position;
      box.orientation = boxes[i].turn.normalized();
      box.friction = 0.45;
      ids.push_back(world.addBody(box));
    }
    double deepest = 0.0;  // in the box's diagonals
    for (int s = 0; s < 15; ++s) {  // 0.25 s: the top box lands within 0.03 s
      world.step(1.0 / 60.0);
      for (std::size_t i = 0; i < ids.size(); ++i) {
        const RigidBodyState st = world.state(ids[i]);
        for (int c = 0; c < 8; ++c) {
          const Vec3 corner(c & 1 ? 1.0 : -1.0, c & 2 ? 1.0 : -1.0, c & 4 ? 1.0 : -1.0);
          const double z = (st.position + st.orientation * corner.cwiseProduct(boxes[i].half)).z();
          deepest = std::max(deepest, -z / (2.0 * boxes[i].half.norm()));
        }
      }
    }
    EXPECT_LT(deepest, 0.01) << contactModelName(model);
  }
}

// A 5 mm cube sliding down a slab turned 40 deg (mu 0.5, below tan 40 deg = 0.84) with every
// model at 16 tests per frame and unlimited: after 0.25 s it has slid a t^2 / 2 with
// a = g (sin 40 - mu cos 40) (analytic; within 10 %, issue 17's criterion), keeps its face on
// the slope and never sinks 1 % of its diagonal into it. The slab's world box holds the cube
// whatever it does, so before a pair the budget interrupted was held only in the world's axes,
// never: with dos and average the cube turned off its roots' one contact and went through the
// slope within 0.12 s. Holds now try the turned body's own axes where the world's find no gap
// (docs/dynamics.md, "Pairs the budget has not reached").
TEST(WorldMassRatio, ACentimetreCubeSlidesDownASlopeWithEveryModelAtSixteenTestsPerFrame) {
  constexpr double kSide = 0.005, kSlope = 40.0 * M_PI / 180.0, kMu = 0.5, kTime = 0.25;
  const Quat turn(Eigen::AngleAxisd(kSlope, Vec3::UnitY()));  // the slope falls toward +x
  const Vec3 up = turn * Vec3::UnitZ(), down = turn * Vec3::UnitX();
  const auto slab = bakeShape(makeBox(Vec3(0.08, 0.015, 0.0025)));
  for (ContactModel model : {ContactModel::kCfm, ContactModel::kExact, ContactModel::kContactTree, ContactModel::kDos,
                             ContactModel::kAverage})
    for (std::uint64_t budget : {std::uint64_t(16), std::uint64_t(0)}) {
      if (sanitizerRun() && budget == 0) continue;
      // Centred at the origin: its top face through 0.0025 up.
      World world = test::staticGroundWorld(model, budget, slab, Vec3::Zero(), turn, kMu);
      const double mass = 1000.0 * kSide * kSide * kSide;
      RigidBodyDesc d = cubeAt(kSide, mass, -0.05 * down + (0.0025 + 0.5 * kSide) * up);
      d.shape = bakeShape(makeBox(Vec3::Constant(0.5 * kSide)));
      d.orientation = turn;
      d.friction = kMu;
      const BodyId id = world.addBody(d);
      double deepest = 0.0;  // below the slope's face, in the cube's diagonals
      const int steps = int(std::lround(kTime * 60.0));
      for (int s = 0; s < steps; ++s) {
        world.step(1.0 / 60.0);
        const RigidBodyState st = world.state(id);
        for (int c = 0; c < 8; ++c) {
          const Vec3 corner(c & 1 ? 1.0 : -1.0, c & 2 ? 1.0 : -1.0, c & 4 ? 1.0 : -1.0);
          const double height = (st.position + st.orientation * (0.5 * kSide * corner)).dot(up) - 0.0025;
          deepest = std::max(deepest, -height / (std::sqrt(3.0) * kSide));
        }
      }
      const RigidBodyState st = world.state(id);
      const double expected = 0.5 * 9.81 * (std::sin(kSlope) - kMu * std::cos(kSlope)) * kTime * kTime;
      const std::string what = std::string(contactModelName(model)) + " at " + std::to_string(budget);
      EXPECT_NEAR((st.position - d.position).dot(down), expected, 0.1 * expected) << what;
      EXPECT_LT(deepest, 0.01) << what;
      // Its face on the slope: the cube's axes still the slope's (within 2 deg, issue 17's slide).
      const Vec3 faceUp = st.orientation * Vec3::UnitZ();
      EXPECT_LT(std::acos(std::clamp(faceUp.dot(up), -1.0, 1.0)) * 180.0 / M_PI, 2.0) << what;
    }
}

// A tower of five boxes ~0.4 m wide, each turned about the vertical, whose middle box is 50 times
// heavier than the two under it and rests under a thin one (a random tower of
// scripts/probe-random-scenes.py, seed 618), at 60 Hz with the default settings: at rest, every
// box slower than issue 17's 5 cm/s over the last 2 of 10 s and within 2 cm of where it started
// (oracle: the stacked start, already at rest). At one substep per frame (the default
// minSubsteps) it shook at up to 13 cm/s for good -- all three models alike, as two whole convex
// boxes get the same separating-axis contacts in each; it now gets a substep per box of the stack
// (docs/dynamics.md, "One step").
TEST(WorldMassRatio, ATowerWithAHeavyBoxInItsMiddleRestsStillAtSixtyHertz) {
  struct Box {
    Vec3 half;
    double density, turnDeg;
  };
  const Box boxes[] = {{{0.214, 0.194, 0.302}, 100.0, 62.5},
                       {{0.205, 0.194, 0.376}, 100.0, 27.9},
                       {{0.205, 0.194, 0.315}, 5000.0, 87.7},
                       {{0.205, 0.194, 0.096}, 1000.0, 44.3},
                       {{0.205, 0.194, 0.313}, 100.0, 12.8}};
  std::vector<std::shared_ptr<const CollisionBody>> shapes;
  for (const Box& b : boxes) shapes.push_back(test::bakeWorldShape(makeBox(b.half)));
  for (ContactModel model : models())
    for (std::uint64_t budget : budgets()) {
      World world = groundWorld(model, budget, 1.0);
      std::vector<BodyId> ids;
      std::vector<Vec3> starts;
      double z = 0.0;
      for (std::size_t i = 0; i < shapes.size(); ++i) {
        const Vec3 size = 2.0 * boxes[i].half;
        RigidBodyDesc box;
        box.shape = shapes[i];
        box.mass = boxes[i].density * size.prod();
        const Vec3 sq = size.cwiseProduct(size);
        box.inertia = (box.mass / 12.0) * Vec3(sq.y() + sq.z(), sq.x() + sq.z(), sq.x() + sq.y()).asDiagonal();
        box.position = Vec3(0.0, 0.0, z + boxes[i].half.z());
        box.orientation = Quat(Eigen::AngleAxisd(boxes[i].turnDeg * M_PI / 180.0, Vec3::UnitZ()));
        box.friction = 0.74;
        z += size.z();
        ids.push_back(world.addBody(box));
        starts.push_back(box.position);
      }
      double fastest = 0.0, farthest = 0.0;
      for (int s = 0; s < 600; ++s) {
        world.step(1.0 / 60.0);
        for (std::size_t i = 0; i < ids.size(); ++i) {
          const RigidBodyState st = world.state(ids[i]);
          if (s >= 480) fastest = std::max(fastest, st.velocity.norm());
          farthest = std::max(farthest, (st.position - starts[i]).norm());
        }
      }
      const std::string what = std::string(contactModelName(model)) + " budget " + std::to_string(budget);
      EXPECT_LT(fastest, 0.05) << what;
      EXPECT_LT(farthest, 0.02) << what;
    }
}

}  // namespace
}  // namespace clod
