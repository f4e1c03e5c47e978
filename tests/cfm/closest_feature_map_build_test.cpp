// Closest feature maps against brute force: every stored (decoded) normal equals the normal of
// the nearest feature among the sphere's responsible triangles, found by a plain loop over them
// with pseudonormals computed here from the mesh (independent of the build path and of the
// proximity layer's pseudonormal tables); lookups use the truly nearest sample; progressive
// refinement follows the paper's halving rule; a box gives face normals at face centres.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "clod/closest_feature_map.h"
#include "clod/error.h"
#include "clod/mesh_io.h"
#include "clod/primitives.h"
#include "clod/proximity.h"
#include "clod/sphere_tree_builder.h"
#include "support/test_scale.h"

namespace clod {
namespace {

using test::sanitizerRun;

TriangleMesh sharedMesh(const char* name) { return loadMesh(std::filesystem::path(CLOD_SHARED_MESH_DIR) / name).mesh; }

double angle(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// Face, edge and vertex normals from the definitions (Baerentzen & Aanaes 2005): a face's unit
// normal; an edge's = normalised sum of its faces' unit normals; a vertex's = normalised sum of
// its faces' unit normals weighted by the face's angle at the vertex.
class PseudonormalOracle {
public:
  explicit PseudonormalOracle(const TriangleMesh& mesh) : mesh_(mesh) {
    vertexNormal_.assign(mesh.vertexCount(), Vec3::Zero());
    for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) {
      const Vec3 n = faceNormal(t);
      if (!n.allFinite()) continue;  // a zero-area triangle has no normal and adds none
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = mesh.triangles[t][k];
        const Vec3& p = mesh.vertices[v];
        const Vec3 e1 = mesh.vertices[mesh.triangles[t][(k + 1) % 3]] - p;
        const Vec3 e2 = mesh.vertices[mesh.triangles[t][(k + 2) % 3]] - p;
        vertexNormal_[v] += angle(e1, e2) * n;
        // try_emplace with an explicit zero: Eigen's default constructor leaves vectors uninitialised.
        edgeNormal_.try_emplace(edgeKey(v, mesh.triangles[t][(k + 1) % 3]), Vec3::Zero()).first->second += n;
      }
    }
  }
  Vec3 faceNormal(std::uint32_t t) const {
    const Triangle& tri = mesh_.triangles[t];
    const Vec3& a = mesh_.vertices[tri[0]];
    return (mesh_.vertices[tri[1]] - a).cross(mesh_.vertices[tri[2]] - a).normalized();
  }
  Vec3 normal(std::uint32_t t, const TrianglePoint& tp) const {
    const Triangle& tri = mesh_.triangles[t];
    switch (tp.feature) {
      case FeatureType::kFace: return faceNormal(t);
      case FeatureType::kEdge: return edgeNormal_.at(edgeKey(tri[tp.localIndex], tri[(tp.localIndex + 1) % 3])).normalized();
      case FeatureType::kVertex: return vertexNormal_[tri[tp.localIndex]].normalized();
    }
    return Vec3::Zero();
  }
  // Normals of every feature of `triangles` whose distance to p is within `tieTolerance` of the
  // smallest: features at equal distance are equally "closest", the build may pick any.
  std::vector<Vec3> closestNormals(const Vec3& p, std::span<const std::uint32_t> triangles, double tieTolerance) const {
    std::vector<std::pair<double, Vec3>> all;
    double best = INFINITY;
    for (std::uint32_t t : triangles) {
      const Triangle& tri = mesh_.triangles[t];
      const TrianglePoint tp = closestPointOnTriangle(p, mesh_.vertices[tri[0]], mesh_.vertices[tri[1]], mesh_.vertices[tri[2]]);
      const double d = std::sqrt(tp.distanceSquared);
      best = std::min(best, d);
      all.emplace_back(d, normal(t, tp));
    }
    std::vector<Vec3> result;
    for (const auto& [d, n] : all) {
      if (d <= best + tieTolerance) result.push_back(n);
    }
    return result;
  }

private:
  static std::pair<std::uint32_t, std::uint32_t> edgeKey(std::uint32_t a, std::uint32_t b) { return {std::min(a, b), std::max(a, b)}; }
  const TriangleMesh& mesh_;
  std::vector<Vec3> vertexNormal_;
  std::map<std::pair<std::uint32_t, std::uint32_t>, Vec3> edgeNormal_;
};

struct BuiltCase {
  TriangleMesh mesh;
  SphereTree tree;
  ClosestFeatureMap maps;
};

BuiltCase buildCase(TriangleMesh mesh, SphereTreeMethod method, const ClosestFeatureMapSettings& settings) {
  const MeshDistance distance(mesh);
  SphereTreeSettings treeSettings;
  treeSettings.method = method;
  treeSettings.medialSamples = 3000;
  // Under sanitizers one level less (an eighth of the spheres to map): every code path stays.
  if (sanitizerRun()) treeSettings.depth = 3;
  SphereTree tree = buildSphereTree(distance, treeSettings);
  ClosestFeatureMap maps = buildClosestFeatureMap(distance, tree, settings);
  return {std::move(mesh), std::move(tree), std::move(maps)};
}

struct OracleCase {
  const char* mesh;  // shared mesh name or "box" / "icosphere"
  SamplingScheme scheme;
  NormalCodec codec;
};

class CfmBuild : public ::testing::TestWithParam<OracleCase> {};

TEST_P(CfmBuild, StoredNormalsEqualTheBruteForceNearestFeatureNormal) {
  const OracleCase param = GetParam();
  const std::string name = param.mesh;
  TriangleMesh mesh = name == "box" ? makeBox(Vec3(1.0, 0.6, 0.3)) : name == "icosphere" ? makeIcosphere(1.0, 2) : sharedMesh(param.mesh);
  ClosestFeatureMapSettings settings;
  settings.scheme = param.scheme;
  settings.codec = param.codec;
  const BuiltCase built = buildCase(std::move(mesh), SphereTreeMethod::kMedial, settings);
  const PseudonormalOracle oracle(built.mesh);
  // Ties: features whose distances differ by rounding only (1e-9 of the diagonal) are equally close.
  const double tie = 1e-9 * built.mesh.bounds().diagonal();
  // The decoded normal may differ from the exact one by the codec's bound; 1e-9 rad for rounding.
  const double tolerance = normalCodecErrorBound(param.codec) + 1e-9;

  std::vector<std::uint32_t> spheres(built.tree.sphereCount());
  for (std::uint32_t i = 0; i < spheres.size(); ++i) spheres[i] = i;
  const std::size_t limit = sanitizerRun() ? 40 : 300;
  if (spheres.size() > limit) {  // the root, then a random subset
    std::mt19937 rng(7);
    std::shuffle(spheres.begin() + 1, spheres.end(), rng);
    spheres.resize(limit);
  }
  std::size_t singles = 0;
  for (std::uint32_t i : spheres) {
    const std::uint32_t level = built.maps.sphereLevel(i);
    const SphereSampling& sampling = built.maps.levelSampling(level);
    const std::span<const std::uint32_t> triangles = built.tree.triangles(i);
    std::vector<Vec3> first;  // the oracle's first candidate per sample
    for (std::uint32_t k = 0; k < sampling.size(); ++k) {
      const Vec3 s = built.tree.center(i) + built.tree.radius[i] * sampling.direction(k);
      const std::vector<Vec3> expected = oracle.closestNormals(s, triangles, tie);
      first.push_back(expected.front());
      const Vec3 stored = built.maps.isSingleNormal(i) ? built.maps.storedNormal(i, 0) : built.maps.storedNormal(i, k);
      double bestAngle = INFINITY;
      std::string seen;
      for (const Vec3& n : expected) {
        bestAngle = std::min(bestAngle, angle(stored, n));
        seen += " (" + std::to_string(n.x()) + ", " + std::to_string(n.y()) + ", " + std::to_string(n.z()) + ")";
      }
      ASSERT_LE(bestAngle, tolerance) << name << " sphere " << i << " (level " << level << ") sample " << k << ": stored ("
                                      << stored.transpose() << "), brute force" << seen
                                      << (built.maps.isSingleNormal(i) ? " (single-normal)" : "");
    }
    if (built.maps.isSingleNormal(i)) {
      ++singles;
    } else {
      // A sphere stores all its samples only when they do not all share one normal.
      bool differs = false;
      for (const Vec3& n : first) differs = differs || angle(n, first[0]) > kSingleNormalAngle;
      EXPECT_TRUE(differs) << name << " sphere " << i << " stores " << sampling.size() << " equal normals";
    }
  }
  if (name == "box") {
    EXPECT_GT(singles, 0u) << "deep spheres of a box bound one face";
  }
}

INSTANTIATE_TEST_SUITE_P(
    Meshes, CfmBuild,
    ::testing::Values(OracleCase{"box", SamplingScheme::kAdaptivePolar, NormalCodec::kOctahedral16},
                      OracleCase{"icosphere", SamplingScheme::kGeodesic, NormalCodec::kOctahedral32},
                      OracleCase{"bunny-1500.obj", SamplingScheme::kAdaptivePolar, NormalCodec::kOctahedral16},
                      OracleCase{"bunny-1500.obj", SamplingScheme::kHealpix, NormalCodec::kOctahedral32},
                      OracleCase{"spot.obj", SamplingScheme::kPolar, NormalCodec::kOctahedral16}),
    [](const ::testing::TestParamInfo<OracleCase>& p) {
      std::string label = p.param.mesh;
      label = label.substr(0, label.find('.'));
      std::replace(label.begin(), label.end(), '-', '_');
      std::string scheme(samplingSchemeName(p.param.scheme));
      std::replace(scheme.begin(), scheme.end(), '-', '_');
      return label + "_" + scheme + "_" + std::string(normalCodecName(p.param.codec));
    });

TEST(CfmLookup, ReturnsTheStoredNormalOfTheTrulyNearestSample) {
  for (SamplingScheme scheme : allSamplingSchemes()) {
    ClosestFeatureMapSettings settings;
    settings.scheme = scheme;
    const BuiltCase built = buildCase(sharedMesh("bunny-1500.obj"), SphereTreeMethod::kOctree, settings);
    std::mt19937_64 rng(11);
    std::normal_distribution<double> gauss;
    std::uniform_int_distribution<std::uint32_t> pick(0, built.tree.sphereCount() - 1);
    const int queries = sanitizerRun() ? 300 : 3000;
    for (int q = 0; q < queries; ++q) {
      const std::uint32_t sphere = q < 50 ? 0 : pick(rng);  // the root has the richest sampling
      const Vec3 d(gauss(rng), gauss(rng), gauss(rng));
      const std::uint32_t index = built.maps.sampleIndex(sphere, 3.7 * d);  // any length works
      const Vec3 normal = built.maps.normal(sphere, 3.7 * d);
      EXPECT_EQ(normal, built.maps.storedNormal(sphere, built.maps.isSingleNormal(sphere) ? 0 : index));
      if (built.maps.isSingleNormal(sphere)) continue;
      const SphereSampling& sampling = built.maps.levelSampling(built.maps.sphereLevel(sphere));
      const Vec3 u = d.normalized();
      double best = -2.0;
      for (std::uint32_t k = 0; k < sampling.size(); ++k) best = std::max(best, u.dot(sampling.direction(k)));
      ASSERT_GE(u.dot(sampling.direction(index)), best - 1e-12) << samplingSchemeName(scheme) << " sphere " << sphere;
    }
  }
}

// Adaptive polar counts from the paper's rule, computed here: 1 pole sample plus
// max(1, round(S sin(i pi / S))) samples on rings i = 1..S-1.
std::uint32_t adaptivePolarCount(int stacks) {
  std::uint32_t count = 1;
  for (int i = 1; i < stacks; ++i) {
    count += static_cast<std::uint32_t>(std::max(1.0, std::round(stacks * std::sin(i * M_PI / stacks))));
  }
  return count;
}

TEST(CfmRefinement, SampleCountsHalveTheStacksPerLevelDownToMinStacks) {
  const TriangleMesh mesh = sharedMesh("bunny-1500.obj");
  const MeshDistance distance(mesh);
  SphereTreeSettings treeSettings;
  treeSettings.method = SphereTreeMethod::kOctree;
  const SphereTree tree = buildSphereTree(distance, treeSettings);
  ASSERT_EQ(tree.levelCount(), 5u);
  struct Expect { int root, minStacks; std::vector<int> stacks; };
  // 10 -> 5 -> 2 -> 1 -> 1 and 16 -> 8 -> 4 -> 2 -> 1 (the paper's halving), floored at minStacks.
  const Expect cases[] = {{10, 1, {10, 5, 2, 1, 1}}, {10, 2, {10, 5, 2, 2, 2}}, {16, 1, {16, 8, 4, 2, 1}}, {16, 4, {16, 8, 4, 4, 4}}};
  for (const Expect& e : cases) {
    ClosestFeatureMapSettings settings;
    settings.rootStacks = e.root;
    settings.minStacks = e.minStacks;
    const ClosestFeatureMap maps = buildClosestFeatureMap(distance, tree, settings);
    std::size_t pool = 0;
    for (std::uint32_t l = 0; l < tree.levelCount(); ++l) {
      EXPECT_EQ(maps.stacksAtTreeLevel(l), e.stacks[l]) << "root " << e.root << " level " << l;
      EXPECT_EQ(maps.samplesAtLevel(l), adaptivePolarCount(e.stacks[l])) << "root " << e.root << " level " << l;
      for (std::uint32_t i = tree.levelBegin(l); i < tree.levelEnd(l); ++i) {
        const std::uint32_t stored = maps.storedNormalCount(i);
        EXPECT_TRUE(stored == 1 || stored == maps.samplesAtLevel(l));
        EXPECT_EQ(stored == 1, maps.isSingleNormal(i) || maps.samplesAtLevel(l) == 1);
        pool += stored;
      }
    }
    EXPECT_EQ(maps.poolSize(), pool);
    EXPECT_EQ(maps.poolBytes(), 2 * pool);
  }
  // The paper's Table 1: 65 root / 3 leaf samples at 10 stacks; 11 leaf samples at 16 stacks.
  EXPECT_EQ(adaptivePolarCount(10), 65u);
  EXPECT_EQ(adaptivePolarCount(2), 3u);
  EXPECT_EQ(adaptivePolarCount(4), 11u);
}

// Face-centre contacts on a box. At the root (the paper's case: a box resolved at the root must not
// get a "round" normal) every face centre gets its face normal with the polar schemes, whose rings
// put a sample close enough to every axis that its sample point projects into the face. Deeper
// down, a face centre can lie inside a sphere far from the sphere's surface, and the sample in its
// direction may then be nearest to an edge or another face: that is the method, not a defect
// (docs/closest-feature-maps.md), so there only single-normal spheres are checked: one that bounds
// part of a face and stores a single normal must store that face's normal.
TEST(CfmBox, FaceCentreContactsGetTheFaceNormal) {
  const Vec3 half(1.0, 0.6, 0.3);
  for (SamplingScheme scheme : allSamplingSchemes()) {
    ClosestFeatureMapSettings settings;
    settings.scheme = scheme;
    const BuiltCase built = buildCase(makeBox(half), SphereTreeMethod::kMedial, settings);
    const PseudonormalOracle oracle(built.mesh);
    const bool polarScheme = scheme == SamplingScheme::kPolar || scheme == SamplingScheme::kAdaptivePolar;
    const double bound = normalCodecErrorBound(settings.codec) + 1e-9;
    int singleChecked = 0;
    for (int axis = 0; axis < 3; ++axis) {
      for (double sign : {-1.0, 1.0}) {
        Vec3 faceNormal = Vec3::Zero();
        faceNormal[axis] = sign;
        const Vec3 centre = sign * half[axis] * faceNormal.cwiseAbs();
        if (polarScheme) {
          EXPECT_LE(angle(built.maps.normal(0, centre - built.tree.center(0)), faceNormal), bound)
              << samplingSchemeName(scheme) << " root, face " << (sign > 0 ? "+" : "-") << "xyz"[axis];
        }
        for (std::uint32_t i = 1; i < built.tree.sphereCount(); ++i) {
          if (!built.maps.isSingleNormal(i)) continue;
          bool onFace = true;
          for (std::uint32_t t : built.tree.triangles(i)) onFace = onFace && oracle.faceNormal(t).dot(faceNormal) > 0.999;
          if (!onFace) continue;
          EXPECT_LE(angle(built.maps.normal(i, centre - built.tree.center(i)), faceNormal), bound)
              << samplingSchemeName(scheme) << " sphere " << i;
          ++singleChecked;
        }
      }
    }
    EXPECT_GT(singleChecked, 0) << samplingSchemeName(scheme) << ": deep spheres of a box bound one face";
  }
}

TEST(CfmData, FromDataRejectsInconsistentMapsNamingTheField) {
  const BuiltCase built = buildCase(makeIcosphere(1.0, 2), SphereTreeMethod::kOctree, {});
  auto code = [&](auto mutate) {
    ClosestFeatureMapData data = built.maps.data();
    mutate(data);
    try {
      ClosestFeatureMap::fromData(std::move(data), built.tree);
    } catch (const Error& e) {
      return e.code();
    }
    return ErrorCode{};
  };
  EXPECT_EQ(code([](ClosestFeatureMapData&) {}), ErrorCode{}) << "unchanged data is accepted";
  EXPECT_EQ(code([](ClosestFeatureMapData& d) { d.codes16.pop_back(); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code([](ClosestFeatureMapData& d) { d.sphereOffset.back() += 1; }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code([](ClosestFeatureMapData& d) { d.sphereSingle.pop_back(); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code([](ClosestFeatureMapData& d) { d.sphereSingle[0] = 7; }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code([](ClosestFeatureMapData& d) { d.levelStacks[1] = 9; }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code([](ClosestFeatureMapData& d) { d.settings.rootStacks = 100000; }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code([](ClosestFeatureMapData& d) { d.settings.codec = static_cast<NormalCodec>(9); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code([](ClosestFeatureMapData& d) { d.codes32.push_back(1); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code([](ClosestFeatureMapData& d) { d.averageNormals[0] = NAN; }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code([](ClosestFeatureMapData& d) { d.averageNormals[0] = 3.0f; }), ErrorCode::kInvalidArgument);
}

TEST(CfmBuildSettings, OutOfRangeSettingsAreInvalidArguments) {
  const MeshDistance distance(makeIcosphere(1.0, 1));
  SphereTreeSettings treeSettings;
  treeSettings.method = SphereTreeMethod::kOctree;
  treeSettings.depth = 1;
  const SphereTree tree = buildSphereTree(distance, treeSettings);
  auto code = [&](ClosestFeatureMapSettings s) {
    try {
      buildClosestFeatureMap(distance, tree, s);
    } catch (const Error& e) {
      return e.code();
    }
    return ErrorCode{};
  };
  ClosestFeatureMapSettings s;
  s.rootStacks = 0;
  EXPECT_EQ(code(s), ErrorCode::kInvalidArgument);
  s = {};
  s.minStacks = s.rootStacks + 1;
  EXPECT_EQ(code(s), ErrorCode::kInvalidArgument);
  s = {};
  s.scheme = static_cast<SamplingScheme>(42);
  EXPECT_EQ(code(s), ErrorCode::kInvalidArgument);
  SphereTree broken = tree;
  broken.triangleList[0] = 1000000;
  EXPECT_THROW(buildClosestFeatureMap(distance, broken, {}), Error);
}

}  // namespace
}  // namespace clod
