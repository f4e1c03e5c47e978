// A box standing over the edge of what it stands on -- a table's edge (an open two-triangle
// floor) and the end of a closed L-shaped body's floor -- stays while its centre of mass is over
// the floor and tips off once it is past the edge (the sphere models: standing over the table's). Before, with the overlap's inner corners as
// its only contacts, the box turned about them and fell off at every budget with cfm, at limited
// budgets with exact, and on the L at an unlimited one too (docs/narrow-phase.md, "Over an
// edge"). Oracle: statics -- a rigid box on a flat support stands exactly when its centre of mass
// lies over the support.
#include <algorithm>
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "clod/primitives.h"
#include "clod/world.h"
#include "support/floor_quad.h"
#include "support/l_shaped_body.h"
#include "support/test_scale.h"
#include "world_test_support.h"

namespace clod {
namespace {

constexpr double kHalf = 0.25;  // the box's half side

using test::solidBoxInertia;
using test::tiltDegrees;

struct Support {
  const char* name;
  TriangleMesh mesh;
  Vec3 standing;  // a box centre over the edge, its centre of mass over the floor (top z = 0)
  Vec3 past;      // a box centre past the edge by 2 cm
  bool open;      // an open sheet
};

TEST(EdgeOverhangWorld, ABoxOverAnEdgeStandsAndOnePastItTipsOffWithEveryModel) {
  const bool sanitized = test::sanitizerRun();
  // The quad's edge y = 1; the L's floor ends at y = 2 (tests/support/l_shaped_body.h).
  const Support supports[] = {{"two-triangle floor", test::makeFloorQuad(1.0, 1.0), Vec3(0.5, 0.95, kHalf), Vec3(0.5, 1.02, kHalf), true},
                              {"L-shaped body", test::makeLShapedBody(), Vec3(-1.0, 1.95, kHalf), Vec3(-1.0, 2.02, kHalf), false}};
  const auto box = test::bakeWorldShape(makeBox(Vec3::Constant(kHalf)));
  for (const Support& support : supports) {
    const auto floor = test::bakeWorldShape(support.mesh);
    for (const ContactModel model : {ContactModel::kCfm, ContactModel::kExact, ContactModel::kContactTree, ContactModel::kDos, ContactModel::kAverage}) {
      for (const std::uint64_t budget : {std::uint64_t(16), std::uint64_t(256), std::uint64_t(0)}) {
        if (sanitized && budget == 256) continue;
        for (const bool past : {false, true}) {
          // At a limited budget the contact tree's coarse cells still hold a box 2 cm past an edge
          // up: their contacts lie within the cell's bound of the edge, 1.4 cm past a sheet's at
          // 256 tests per frame, and its field reads a little inside beyond the L's edge at 16; at
          // 256 the L's level-3-4 cells give samples 3.3 cm past its edge, touching within their
          // 4.4 cm bounds. (That box tipped before only because the manifold kept one of its two
          // corners there, picked among interior samples.) At full depth a field ends at its
          // border (docs/contact-tree.md, "Sheets").
          if (past && model == ContactModel::kContactTree && budget != 0) continue;
          // The sphere models' contacts are their spheres': a floor's leaf sphere reaches past its
          // edge and holds a box 2 cm past it up. Over the L's floor, whose box holds the box's
          // centre of mass, their contacts take the L's own surface normals (docs/dynamics.md,
          // "Sphere models' interrupted contacts"; D&O's leaned, and the box slid off at every
          // budget before), but the boxes give no hold: at 16 tests per frame the roots'
          // contacts lie inside the edge, and the box turns off them (docs/dynamics.md, "Known
          // limits").
          // Standing over the table's edge is theirs to get right at every budget: at limited ones
          // the roots' contacts lay inside the edge, and the box turned off them until the pair's
          // hold reached the edge (docs/dynamics.md, "Pairs the budget has not reached").
          const bool sphereModel = model == ContactModel::kDos || model == ContactModel::kAverage;
          if (sphereModel && (past || (!support.open && budget == 16))) continue;
          World world = test::staticGroundWorld(model, budget, floor, Vec3::Zero(), Quat::Identity(), 0.6);
          RigidBodyDesc d;
          d.shape = box;
          d.mass = 1.0;
          d.inertia = Mat3::Identity() * (1.0 / 6.0 * 4.0 * kHalf * kHalf);  // solid cube: m (2h)^2 / 6
          d.friction = 0.6;
          d.position = past ? support.past : support.standing;
          const BodyId id = world.addBody(d);
          for (int i = 0; i < 120; ++i) world.step(1.0 / 60.0);
          const RigidBodyState s = world.state(id);
          const std::string what = std::string(support.name) + ", " + std::string(contactModelName(model)) + " at " +
                                   std::to_string(budget) + (past ? ", past the edge" : ", over the edge");
          if (past) {
            // Tipped off: 2 s of fall from the edge is metres.
            EXPECT_LT(s.position.z(), -1.0) << what;
            continue;
          }
          // A resting box settles by its slop and one frame's fall (g dt^2, 2.7 mm at 60 Hz);
          // tipping off is metres.
          EXPECT_LT((s.position - d.position).norm(), 0.01) << what;
          EXPECT_LT(tiltDegrees(s.orientation), 1.0) << what;
          EXPECT_LT(s.velocity.norm(), 0.01) << what;
        }
      }
    }
  }
}

// A tall box (0.3 x 0.5 x 1 sides) standing on a slab's end with its centre of mass 4 cm inside
// the end and 11 cm of it past, at 1 m and at 1 cm, with every model and budget. At 16 tests
// per frame the sphere models' roots' contacts lie well inside the end, beyond the centre of
// mass; the box turned off them and fell off the slab at 1 m (dos and average) and tipped over
// at 1 cm. Fixed by holding the pair at the slab's end (a support point past it moves onto the
// end, the box's face above it from the box's face planes) and by holding a carried-on
// interrupted answer as a fresh one (docs/dynamics.md, "Pairs the budget has not reached").
// Oracle: statics, as above.
TEST(EdgeOverhangWorld, ATallBoxOverASlabsEndStandsWithEveryModelAndBudget) {
  const bool sanitized = test::sanitizerRun();
  const Vec3 half(0.15, 0.25, 0.5);
  const auto box = test::bakeWorldShape(makeBox(half));
  const auto slab = test::bakeWorldShape(makeBox(Vec3(2.0, 2.0, 0.25)));
  for (const double scale : {1.0, 0.01})
    for (const ContactModel model :
         {ContactModel::kCfm, ContactModel::kExact, ContactModel::kContactTree, ContactModel::kDos, ContactModel::kAverage})
      for (const std::uint64_t budget : {std::uint64_t(16), std::uint64_t(256), std::uint64_t(0)}) {
        if (sanitized && (budget == 256 || scale != 1.0)) continue;
        // Top at z = 0, end at x = -2 scale.
        World world = test::staticGroundWorld(model, budget, slab, Vec3(0.0, 0.0, -0.25 * scale), Quat::Identity(), 0.6, scale);
        RigidBodyDesc d;
        d.shape = box;
        d.mass = 150.0 * scale * scale * scale;  // water: 0.3 x 0.5 x 1 m^3 at 1 m
        d.inertia = solidBoxInertia(scale * half, d.mass);
        d.friction = 0.6;
        d.position = scale * Vec3(-2.0 + 0.04, -0.3, half.z());  // 11 cm past the end (at 1 m)
        const BodyId id = world.addBody(d, scale);
        for (int i = 0; i < 120; ++i) world.step(1.0 / 60.0);
        const RigidBodyState s = world.state(id);
        const std::string what = std::string(contactModelName(model)) + " at " + std::to_string(budget) + ", scale " +
                                 std::to_string(scale);
        // As above, in box heights: its slop and a frame's fall; tipping off is its size.
        EXPECT_LT((s.position - d.position).norm() / scale, 0.01) << what;
        EXPECT_LT(tiltDegrees(s.orientation), 1.0) << what;
        EXPECT_LT(s.velocity.norm() / scale, 0.01) << what;
      }
}

// A thin tall box (0.86 x 0.28 x 0.96 at 1 m) standing over the edge of a floor tessellated into
// 0.5 m squares, its footprint across two rows of them and 7 cm past the edge, its centre of mass
// 36 cm inside (a random scene of issue 17's overhangs, scaled). Before, with exact at an
// unlimited budget it toppled sideways at 1 cm: resting at rounding depth, the points where its
// side faces cross the floor were dropped as grazing, and the corner of its footprint at the
// edge had no contact; the contact tree pushed it 1 mm (10 % of its size) back from the edge,
// whose sheet read inside just under the plane beyond the border. Oracle: statics, as above.
TEST(EdgeOverhangWorld, AThinBoxOverATessellatedFloorsEdgeStandsWithEveryModel) {
  const bool sanitized = test::sanitizerRun();
  const Vec3 half(0.43, 0.1385, 0.48);
  const auto box = test::bakeWorldShape(makeBox(half));
  // Edge at x = -2; the mesh at z = 0.25 placed 0.25 down, as a scene's ground often is: its top
  // at 0 up to rounding, where the box's bottom starts.
  const auto floor = test::bakeWorldShape(test::makeFloorGrid(2.0, 2.0, 8, 0.25));
  for (const double scale : {1.0, 0.01})
    for (const ContactModel model : {ContactModel::kCfm, ContactModel::kExact, ContactModel::kContactTree})
      for (const std::uint64_t budget : {std::uint64_t(16), std::uint64_t(256), std::uint64_t(0)}) {
        if (sanitized && budget == 256) continue;
        World world = test::staticGroundWorld(model, budget, floor, Vec3(0.0, 0.0, -0.25 * scale), Quat::Identity(), 0.89, scale);
        RigidBodyDesc d;
        d.shape = box;
        d.mass = 8.0 * half.prod() * 1000.0 * scale * scale * scale;  // water
        d.inertia = solidBoxInertia(scale * half, d.mass);
        d.friction = 0.89;
        d.position = scale * Vec3(-1.644, 0.877, half.z());  // across y = 1 (its +y side 1.6 cm over it)
        const BodyId id = world.addBody(d, scale);
        for (int i = 0; i < 96; ++i) world.step(1.0 / 240.0);
        const RigidBodyState s = world.state(id);
        const std::string what = std::string(contactModelName(model)) + " at " + std::to_string(budget) + ", scale " +
                                 std::to_string(scale);
        // Issue 17's resting criteria in box heights (2 cm, 1 deg, 5 cm/s at 1 m).
        EXPECT_LT((s.position - d.position).norm() / scale, 0.02) << what;
        EXPECT_LT(tiltDegrees(s.orientation), 1.0) << what;
        EXPECT_LT(s.velocity.norm() / scale, 0.05) << what;
      }
}

}  // namespace
}  // namespace clod
