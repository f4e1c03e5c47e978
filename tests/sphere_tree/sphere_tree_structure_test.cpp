// Structural invariants of built sphere-trees, and settings validation.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <numeric>

#include "clod/error.h"
#include "clod/primitives.h"
#include "clod/proximity.h"
#include "clod/sphere_tree_builder.h"
#include "sphere_tree_structure_check.h"
#include "support/test_scale.h"

namespace clod {
namespace {

TEST(SphereTreeMethod, NamesRoundTripAndUnknownNamesAreRejected) {
  for (SphereTreeMethod m : {SphereTreeMethod::kOctree, SphereTreeMethod::kMedial})
    EXPECT_EQ(parseSphereTreeMethod(sphereTreeMethodName(m)), m);
  try {
    parseSphereTreeMethod("voronoi");
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("voronoi"), std::string::npos);
  }
}

TEST(SphereTreeBuilder, OutOfRangeSettingsThrowInvalidArgumentNamingTheSetting) {
  const MeshDistance box(makeBox(Vec3(1, 2, 3)));
  struct Case {
    SphereTreeSettings settings;
    const char* name;
  };
  std::vector<Case> cases;
  SphereTreeSettings s;
  s.branching = 1;
  cases.push_back({s, "branching"});
  s = {};
  s.branching = 65;
  cases.push_back({s, "branching"});
  s = {};
  s.depth = 9;
  cases.push_back({s, "depth"});
  s = {};
  s.medialSamples = 10;
  cases.push_back({s, "medialSamples"});
  for (const Case& c : cases) {
    try {
      buildSphereTree(box, c.settings);
      ADD_FAILURE() << "no exception for " << c.name;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find(c.name), std::string::npos) << e.what();
    }
  }
}

TEST(SphereTreeBuilder, TreesHaveConsistentLevelsChildrenParentsAndTriangleListsForAnyBranching) {
  const MeshDistance sphere(makeIcosphere(1.0, 3));
  const MeshDistance cylinder(makeCylinder(0.5, 2.0, 24));
  struct Builder {
    SphereTreeMethod method;
    MedialReduction reduction;
  };
  for (const MeshDistance* mesh : {&sphere, &cylinder})
    for (const Builder builder : {Builder{SphereTreeMethod::kOctree, MedialReduction::kBest},
                                  Builder{SphereTreeMethod::kMedial, MedialReduction::kBest},
                                  Builder{SphereTreeMethod::kMedial, MedialReduction::kMergeBurst}})
      for (std::uint32_t branching : {2u, 4u, 8u, 27u})
        for (std::uint32_t depth : {0u, 1u, 3u}) {
          // Under sanitizers: the binary and the octree-like factor only (every code path; a
          // factor of 27 at depth 3 alone is 20k leaves).
          if (test::sanitizerRun() && branching != 2 && branching != 8) continue;
          // ... and the 8-ary trees to depth 2: depth 3 adds leaves, not code paths.
          if (test::sanitizerRun() && branching == 8 && depth == 3) depth = 2;
          // The merge/burst reduction alone at the usual factors only, to keep the runner short
          // (the default medial builder runs it at every factor).
          if (builder.reduction == MedialReduction::kMergeBurst && branching != 2 && branching != 8) continue;
          SCOPED_TRACE(std::string(sphereTreeMethodName(builder.method)) + " reduction " +
                       std::to_string(static_cast<int>(builder.reduction)) + " branching " +
                       std::to_string(branching) + " depth " + std::to_string(depth));
          SphereTreeSettings settings;
          settings.method = builder.method;
          settings.medialReduction = builder.reduction;
          settings.branching = branching;
          settings.depth = depth;
          settings.medialSamples = 2000;
          const SphereTree tree = buildSphereTree(*mesh, settings);
          test::expectWellFormedTree(tree, mesh->mesh(), settings);
        }
}

TEST(SphereTreeBuilder, MedialNodesUseTheFullBranchingFactorWhenThereIsEnoughSurface) {
  // An icosphere of 1280 triangles has far more surface than 8^3 clusters need.
  const MeshDistance sphere(makeIcosphere(1.0, 3));
  for (MedialReduction reduction : {MedialReduction::kBest, MedialReduction::kMergeBurst, MedialReduction::kKMeans}) {
    SphereTreeSettings settings;
    settings.depth = 3;
    settings.medialSamples = 4000;
    settings.medialReduction = reduction;
    const SphereTree tree = buildSphereTree(sphere, settings);
    for (std::uint32_t l = 0; l <= 3; ++l)
      EXPECT_EQ(tree.levelEnd(l) - tree.levelBegin(l), std::uint32_t(1) << (3 * l))
          << "reduction " << static_cast<int>(reduction) << ", level " << l;
  }
}

TEST(SphereTreeBuilder, BuildsAreDeterministic) {
  const MeshDistance cylinder(makeCylinder(0.5, 2.0, 24));
  for (int builder = 0; builder < 4; ++builder) {
    SCOPED_TRACE(builder);
    SphereTreeSettings settings;
    settings.medialSamples = 2000;
    settings.depth = test::sanitizerRun() ? 2 : 3;  // the same code at an eighth of the leaves
    if (builder == 0) settings.method = SphereTreeMethod::kOctree;
    if (builder == 2) settings.medialReduction = MedialReduction::kMergeBurst;
    if (builder == 3) settings.medialReduction = MedialReduction::kKMeans;
    const SphereTree a = buildSphereTree(cylinder, settings);
    SphereTree b;
    {
      // Same tree on one thread as on all of them.
      const tbb::global_control oneThread(tbb::global_control::max_allowed_parallelism, 1);
      b = buildSphereTree(cylinder, settings);
    }
    EXPECT_EQ(a.radius, b.radius);
    EXPECT_EQ(a.centerX, b.centerX);
    EXPECT_EQ(a.triangleList, b.triangleList);
    EXPECT_EQ(a.levelOffsets, b.levelOffsets);
  }
}

}  // namespace
}  // namespace clod
