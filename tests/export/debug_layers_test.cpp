// Debug layers against the structures they show and against analytic answers for a box: the
// closest feature of an outside point (face / edge / corner region) and the box's exact signed
// distance. layers.json is read back with nlohmann::json, not with the writer.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "clod/bake.h"
#include "clod/debug_layers.h"
#include "clod/error.h"
#include "clod/primitives.h"

namespace clod {
namespace {

const Vec3 kHalf(0.6, 0.4, 0.25);

const BakeContents& boxBake() {
  static const BakeContents bake = [] {
    BakeSettings s;
    s.sphereTree.method = SphereTreeMethod::kOctree;
    s.sphereTree.depth = 2;
    s.measureFit = false;
    s.contactTree.maxDepth = 5;
    return bakeMesh(makeBox(kHalf), s).contents;
  }();
  return bake;
}

// Exact signed distance of the box (negative inside): the standard closed form
// |max(q, 0)| + min(max_i q_i, 0) with q = |p| - h.
double boxDistance(const Vec3& p) {
  const Vec3 q = p.cwiseAbs() - kHalf;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

TEST(DebugLayers, SphereTreeLayerHoldsEveryLevelsSpheres) {
  const SphereTree& tree = boxBake().sphereTree;
  const SphereTreeLayer layer = makeSphereTreeLayer(tree);
  ASSERT_EQ(layer.levels.size(), tree.levelCount());
  for (std::uint32_t l = 0; l < tree.levelCount(); ++l) {
    ASSERT_EQ(layer.levels[l].size(), 4u * (tree.levelEnd(l) - tree.levelBegin(l)));
    for (std::uint32_t s = tree.levelBegin(l), i = 0; s < tree.levelEnd(l); ++s, i += 4) {
      EXPECT_FLOAT_EQ(layer.levels[l][i], float(tree.centerX[s]));
      EXPECT_FLOAT_EQ(layer.levels[l][i + 3], float(tree.radius[s]));
    }
  }
}

TEST(DebugLayers, RootCfmSamplesLieOnTheRootSphereWithTheBoxsClosestFeatureNormal) {
  const BakeContents& bake = boxBake();
  ASSERT_TRUE(bake.closestFeatureMap);
  const std::vector<CfmSampleLevel> levels = makeCfmSampleLayer(*bake.closestFeatureMap, bake.sphereTree);
  ASSERT_FALSE(levels.empty());
  ASSERT_EQ(levels[0].level, 0u);
  const Vec3 c = bake.sphereTree.center(0);
  const double r = bake.sphereTree.radius[0], diag = 2 * kHalf.norm();
  // 16-bit octahedral normals are within ~0.95 degrees (closest_feature_map.h); allow 1.0.
  const double cosTol = std::cos(1.0 * M_PI / 180.0);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < levels[0].points.size(); i += 3) {
    const Vec3 p(levels[0].points[i], levels[0].points[i + 1], levels[0].points[i + 2]);
    const Vec3 n(levels[0].normals[i], levels[0].normals[i + 1], levels[0].normals[i + 2]);
    EXPECT_NEAR((p - c).norm(), r, 1e-6 * diag);  // float storage of a point ~ 1e-7 relative
    EXPECT_NEAR(n.norm(), 1.0, 1e-6);
    // The root sphere holds the whole box, so every sample is outside or on it: the closest
    // feature is the face, edge or corner of the region of p, whose (pseudo)normal is the
    // normalised sum of the face normals of the axes where |p_i| > h_i.
    Vec3 expected = Vec3::Zero();
    bool ambiguous = false;
    for (int a = 0; a < 3; ++a) {
      const double excess = std::abs(p[a]) - kHalf[a];
      if (std::abs(excess) < 1e-6 * diag) ambiguous = true;  // on a region border: two answers
      if (excess > 0) expected[a] = p[a] > 0 ? 1.0 : -1.0;
    }
    if (ambiguous || expected.isZero()) continue;
    EXPECT_GE(n.dot(expected.normalized()), cosTol) << "sample at " << p.transpose();
    ++checked;
  }
  EXPECT_GT(checked, levels[0].points.size() / 3 / 2) << "most samples are away from region borders";
  for (const CfmSampleLevel& level : levels)
    for (std::size_t i = 0; i < level.normals.size(); i += 3)
      EXPECT_NEAR(Vec3(level.normals[i], level.normals[i + 1], level.normals[i + 2]).norm(), 1.0, 1e-6);
}

TEST(DebugLayers, CfmSampleCapTakesWholeLevelsFromTheRoot) {
  const BakeContents& bake = boxBake();
  const ClosestFeatureMap& map = *bake.closestFeatureMap;
  const SphereTree& tree = bake.sphereTree;
  auto samples = [&](std::uint32_t l) { return map.samplesAtLevel(l) * (tree.levelEnd(l) - tree.levelBegin(l)); };
  EXPECT_EQ(makeCfmSampleLayer(map, tree, 1).size(), 1u) << "the root level is always taken";
  const auto two = makeCfmSampleLayer(map, tree, samples(0) + samples(1));
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[1].points.size(), 3u * samples(1));
  EXPECT_EQ(makeCfmSampleLayer(map, tree, samples(0) + samples(1) - 1).size(), 1u);
  EXPECT_EQ(makeCfmSampleLayer(map, tree, std::numeric_limits<std::uint32_t>::max()).size(), tree.levelCount());
}

TEST(DebugLayers, ContactTreeCellsAreInsideTheRootCubeAndNearTheBoxSurface) {
  const BakeContents& bake = boxBake();
  ASSERT_TRUE(bake.contactTree);
  const ContactTree& tree = *bake.contactTree;
  const ContactTreeLayer layer = makeContactTreeLayer(tree, std::numeric_limits<std::uint32_t>::max());
  ASSERT_GT(layer.cellCount(), 0u);
  EXPECT_EQ(layer.depthsIncluded, tree.depthCount());
  EXPECT_EQ(layer.halfSpaces.size(), 4u * layer.cellCount());
  EXPECT_EQ(layer.cellCount(), tree.halfSpaces.size()) << "every surface cell once";
  const double diag = 2 * kHalf.norm();
  // Float storage of coordinates and offsets: ~1e-7 relative to the diagonal; 1e-5 leaves margin.
  const double tol = 1e-5 * diag;
  std::size_t flatCells = 0;
  for (std::uint32_t i = 0; i < layer.cellCount(); ++i) {
    const Vec3 centre(layer.cells[5 * i], layer.cells[5 * i + 1], layer.cells[5 * i + 2]);
    const double half = layer.cells[5 * i + 3];
    const int depth = int(layer.cells[5 * i + 4]);
    EXPECT_NEAR(half, 0.5 * tree.rootSize / double(1 << depth), tol);
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(centre[a] - half, tree.origin[a] - tol);
      EXPECT_LE(centre[a] + half, tree.origin[a] + tree.rootSize + tol);
    }
    // A surface cell has the surface within half its diagonal of its centre (docs/contact-tree.md).
    EXPECT_LE(std::abs(boxDistance(centre)), std::sqrt(3.0) * half + tol) << "cell " << i;
    const Vec3 n(layer.halfSpaces[4 * i], layer.halfSpaces[4 * i + 1], layer.halfSpaces[4 * i + 2]);
    const double offset = layer.halfSpaces[4 * i + 3];
    EXPECT_NEAR(n.norm(), 1.0, 1e-5);
    // Where only one face is near (the centre is over a face's interior, two cell diagonals
    // from its border), the field is linear there and the plane is the face's: n = +-e_a,
    // n.x = h_a.
    const Vec3 q = centre.cwiseAbs() - kHalf;
    int a;
    q.maxCoeff(&a);
    bool flat = true;
    for (int b = 0; b < 3; ++b)
      if (b != a && q[b] > -4 * std::sqrt(3.0) * half) flat = false;
    if (!flat) continue;
    ++flatCells;
    Vec3 face = Vec3::Zero();
    face[a] = centre[a] > 0 ? 1.0 : -1.0;
    EXPECT_NEAR((n - face).norm(), 0.0, 1e-3) << "cell " << i;
    EXPECT_NEAR(offset, kHalf[a], 1e-3 * diag) << "cell " << i;
  }
  EXPECT_GT(flatCells, 0u);
}

TEST(DebugLayers, ContactTreeCapTakesWholeDepths) {
  const ContactTree& tree = *boxBake().contactTree;
  const ContactTreeLayer all = makeContactTreeLayer(tree, std::numeric_limits<std::uint32_t>::max());
  const ContactTreeLayer few = makeContactTreeLayer(tree, all.cellCount() - 1);
  EXPECT_LT(few.depthsIncluded, all.depthsIncluded);
  // Exactly the cells of depths < depthsIncluded.
  std::uint32_t expected = 0;
  for (std::uint32_t i = 0; i < all.cellCount(); ++i) expected += all.cells[5 * i + 4] < float(few.depthsIncluded);
  EXPECT_EQ(few.cellCount(), expected);
  EXPECT_GE(makeContactTreeLayer(tree, 1).cellCount(), 1u) << "the first depth with surface cells is always taken";
}

FrameSeries twoFrames() {
  FrameSeries f;
  f.time = {0.0, 0.5};
  f.step = {0, 30};
  f.kineticEnergy = {1.0, 2.0};
  f.potentialEnergy = {10.0, 8.5};
  f.contacts = {0, 2};
  f.testsSpent = {0, 77};
  f.testsBudget = {0, 100};
  f.contactOffsets = {0, 0, 2};
  f.contactData = {0.5f, 0, 0, 0, 0, 1, 0.01f, -0.5f, 0, 0, 0, 0, 1, 0.02f};
  return f;
}

TEST(DebugLayers, EncodedJsonHasTheContractKeysAndOmitsAbsentLayers) {
  DebugLayers layers;
  layers.frames = twoFrames();
  BodyDebugLayers& a = layers.bodies.emplace_back();
  a.name = "box \"a\"";
  a.node = 0;
  a.sphereTree = makeSphereTreeLayer(boxBake().sphereTree);
  a.cfmSamples = makeCfmSampleLayer(*boxBake().closestFeatureMap, boxBake().sphereTree);
  a.contactTree = makeContactTreeLayer(*boxBake().contactTree);
  BodyDebugLayers& b = layers.bodies.emplace_back();
  b.name = "plain";
  b.node = 1;
  const nlohmann::json j = nlohmann::json::parse(encodeDebugLayers(layers));
  EXPECT_EQ(j["format"], "clod-layers");
  EXPECT_EQ(j["version"], 1);
  EXPECT_EQ(j["frames"]["time"], nlohmann::json({0.0, 0.5}));
  EXPECT_EQ(j["frames"]["total_energy"], nlohmann::json({11.0, 10.5}));  // kinetic + potential
  EXPECT_EQ(j["frames"]["contacts"], nlohmann::json({0, 2}));
  EXPECT_EQ(j["frames"]["tests_spent"], nlohmann::json({0, 77}));
  EXPECT_EQ(j["frames"]["tests_budget"], nlohmann::json({0, 100}));
  EXPECT_EQ(j["contacts"]["frame_offsets"], nlohmann::json({0, 0, 2}));
  ASSERT_EQ(j["contacts"]["data"].size(), 14u);
  EXPECT_FLOAT_EQ(j["contacts"]["data"][13].get<float>(), 0.02f);  // shortest float text reads back exactly
  ASSERT_EQ(j["bodies"].size(), 2u);
  EXPECT_EQ(j["bodies"][0]["name"], "box \"a\"");
  EXPECT_EQ(j["bodies"][0]["sphere_tree"]["levels"].size(), boxBake().sphereTree.levelCount());
  EXPECT_EQ(j["bodies"][0]["contact_tree"]["cells"].size(), 5 * layers.bodies[0].contactTree->cellCount());
  EXPECT_EQ(j["bodies"][0]["cfm_samples"][0]["level"], 0);
  EXPECT_EQ(j["bodies"][1]["node"], 1);
  for (const char* key : {"sphere_tree", "cfm_samples", "contact_tree"}) EXPECT_FALSE(j["bodies"][1].contains(key)) << key;

  layers.frames.reset();
  const nlohmann::json bake = nlohmann::json::parse(encodeDebugLayers(layers));
  EXPECT_FALSE(bake.contains("frames"));
  EXPECT_FALSE(bake.contains("contacts"));
}

TEST(DebugLayers, InconsistentFramesOrNonFiniteValuesThrowInvalidArgument) {
  auto expectInvalid = [](const FrameSeries& f, const std::string& fragment) {
    DebugLayers layers;
    layers.frames = f;
    try {
      encodeDebugLayers(layers);
      ADD_FAILURE() << "no error; expected " << fragment;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  FrameSeries f = twoFrames();
  f.testsSpent.pop_back();
  expectInvalid(f, "tests_spent");
  f = twoFrames();
  f.contactOffsets = {0, 2, 1};
  expectInvalid(f, "frame_offsets[2]");
  f = twoFrames();
  f.contactData.pop_back();
  expectInvalid(f, "contacts.data");
  f = twoFrames();
  f.kineticEnergy[1] = std::numeric_limits<double>::infinity();
  expectInvalid(f, "kinetic_energy[1]");
}

}  // namespace
}  // namespace clod
