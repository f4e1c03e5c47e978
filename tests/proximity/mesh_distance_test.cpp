#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "clod/error.h"
#include "clod/mesh_io.h"
#include "clod/mesh_topology.h"
#include "clod/primitives.h"
#include "clod/proximity.h"
#include "oracle.h"
#include "support/floor_quad.h"

namespace {

using clod::FeatureType;
using clod::MeshDistance;
using clod::SignMethod;
using clod::TriangleMesh;
using clod::Vec3;

// ---- test meshes -------------------------------------------------------------------------

// A unit-ish icosphere plus exactly degenerate triangles (a repeated corner, a collinear
// triple, a needle) scattered over it: distances must still be exact and never NaN.
TriangleMesh icosphereWithDegenerates() {
  TriangleMesh m = clod::makeIcosphere(1.0, 2);
  const std::uint32_t n = m.vertexCount();
  m.vertices.push_back(Vec3(0.3, 0.3, 0.3));
  m.vertices.push_back(Vec3(0.6, 0.6, 0.6));
  m.vertices.push_back(Vec3(1.5, 1.5, 1.5));
  m.vertices.push_back(Vec3(1.5, 1.5, 1.5 + 1e-12));
  m.triangles.push_back({0, 0, 1});          // two equal corners
  m.triangles.push_back({n, n + 1, n + 2});  // collinear
  m.triangles.push_back({2, n + 2, n + 3});  // needle
  m.triangles.push_back({n + 3, n + 3, n + 3});  // a point
  return m;
}

struct NamedMesh {
  std::string name;
  bool closed;  // closed and consistently oriented: ray parity is a valid inside test
};

const std::vector<NamedMesh>& meshNames() {
  static const std::vector<NamedMesh> names = {
      {"box", true},          {"icosphere", true},      {"cylinder", true},
      {"degenerate", false},  {"bunny-1500.obj", false}, {"spot.obj", true},
      {"cow.obj", false},  // closed edges, but parts overlap (winding number 2): no parity test      {"fandisk.obj", true},     {"rocker-arm.obj", true},
      {"teapot.obj", false},  {"suzanne.obj", false},    {"stanford-bunny.obj", false},
  };
  return names;
}

const TriangleMesh& testMesh(const std::string& name) {
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<TriangleMesh>> cache;
  std::lock_guard lock(mutex);
  auto& slot = cache[name];
  if (!slot) {
    if (name == "box") {
      slot = std::make_unique<TriangleMesh>(clod::makeBox(Vec3(1.0, 0.5, 2.0)));
    } else if (name == "icosphere") {
      slot = std::make_unique<TriangleMesh>(clod::makeIcosphere(1.5, 3));
    } else if (name == "cylinder") {
      slot = std::make_unique<TriangleMesh>(clod::makeCylinder(0.5, 2.0, 24));
    } else if (name == "degenerate") {
      slot = std::make_unique<TriangleMesh>(icosphereWithDegenerates());
    } else {
      slot = std::make_unique<TriangleMesh>(
          clod::loadMesh(std::filesystem::path(CLOD_SHARED_MESH_DIR) / name).mesh);
    }
  }
  return *slot;
}

const MeshDistance& meshDistance(const std::string& name, bool forceWinding = false) {
  static std::mutex mutex;
  static std::map<std::pair<std::string, bool>, std::unique_ptr<MeshDistance>> cache;
  const TriangleMesh& mesh = testMesh(name);
  std::lock_guard lock(mutex);
  auto& slot = cache[{name, forceWinding}];
  if (!slot) {
    clod::MeshDistanceSettings settings;
    settings.forceWindingNumber = forceWinding;
    slot = std::make_unique<MeshDistance>(mesh, settings);
  }
  return *slot;
}

// Uniform points in the bounding box grown by 10% of its diagonal on every side, plus points
// within 0.5% of the diagonal of random surface points (where feature classification is hard).
std::vector<Vec3> samplePoints(const TriangleMesh& mesh, int boxCount, int nearCount, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const clod::Aabb box = mesh.bounds();
  const double grow = 0.1 * box.diagonal();
  std::vector<Vec3> points;
  for (int i = 0; i < boxCount; ++i) {
    Vec3 p;
    for (int k = 0; k < 3; ++k) {
      p[k] = std::uniform_real_distribution<double>(box.min[k] - grow, box.max[k] + grow)(rng);
    }
    points.push_back(p);
  }
  std::uniform_int_distribution<std::uint32_t> pick(0, mesh.triangleCount() - 1);
  std::uniform_real_distribution<double> unit(0, 1), offset(-0.005, 0.005);
  std::normal_distribution<double> gauss;
  for (int i = 0; i < nearCount; ++i) {
    const std::uint32_t t = pick(rng);
    double r1 = unit(rng), r2 = unit(rng);
    if (r1 + r2 > 1) r1 = 1 - r1, r2 = 1 - r2;
    const Vec3 onSurface = mesh.corner(t, 0) + r1 * (mesh.corner(t, 1) - mesh.corner(t, 0)) +
                           r2 * (mesh.corner(t, 2) - mesh.corner(t, 0));
    const Vec3 dir = Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized();
    points.push_back(onSurface + offset(rng) * box.diagonal() * dir);
  }
  return points;
}

int scaled(int full, int sanitizer) { return oracle::sanitizerRun() ? sanitizer : full; }

class MeshDistanceOnCorpus : public ::testing::TestWithParam<NamedMesh> {};

std::string paramName(const ::testing::TestParamInfo<NamedMesh>& info) {
  std::string s = info.param.name;
  for (char& c : s) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return s;
}

// ---- closest point vs brute force ----------------------------------------------------------

// Distance to the geometry of a mesh feature, computed independently of the code under test.
double featureDistance(const TriangleMesh& mesh, const clod::MeshTopology& topology, clod::MeshFeature f,
                       const Vec3& p, bool* faceInterior) {
  *faceInterior = true;
  switch (f.type) {
    case FeatureType::kVertex: return (p - mesh.vertices[f.index]).norm();
    case FeatureType::kEdge: {
      const clod::Edge e = topology.edges()[f.index];
      return oracle::closestOnSegment(p, mesh.vertices[e.v0], mesh.vertices[e.v1], 0).distance;
    }
    case FeatureType::kFace: {
      const auto h = oracle::closestOnTriangle(p, mesh.corner(f.index, 0), mesh.corner(f.index, 1),
                                               mesh.corner(f.index, 2));
      *faceInterior = h.type == FeatureType::kFace;
      return h.distance;
    }
  }
  return 0.0;
}

TEST_P(MeshDistanceOnCorpus, ClosestPointMatchesBruteForceOverAllTriangles) {
  const TriangleMesh& mesh = testMesh(GetParam().name);
  const MeshDistance& md = meshDistance(GetParam().name);
  const clod::MeshTopology& topology = md.topology();
  const double diagonal = mesh.bounds().diagonal();
  // Both sides compute the same point-triangle distances in double with different operation
  // orders; 1e-9 of the diagonal is ~1e6 ulps of the coordinates, far above that noise and far
  // below any real difference between two features.
  const double tol = 1e-9 * diagonal;
  const auto points = samplePoints(mesh, scaled(10000, 400), scaled(2000, 100), 1234);
  std::vector<oracle::MeshHit> reference(points.size());
  const oracle::BruteForce bruteForce(mesh);
  tbb::parallel_for(std::size_t(0), points.size(), [&](std::size_t i) { reference[i] = bruteForce.closest(points[i]); });
  const oracle::Normals normals = oracle::normalsOf(mesh);

  int sameFeature = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    const clod::ClosestPoint c = md.closestPoint(p);
    const double expected = reference[i].hit.distance;
    ASSERT_NEAR(c.distance, expected, tol) << "point " << i << " " << p.transpose();
    ASSERT_NEAR((c.point - p).norm(), c.distance, tol) << "point " << i;
    // The triangle reported must contain the closest point.
    const auto onTriangle = oracle::closestOnTriangle(c.point, mesh.corner(c.triangle, 0),
                                                      mesh.corner(c.triangle, 1), mesh.corner(c.triangle, 2));
    ASSERT_LE(onTriangle.distance, tol) << "point " << i;
    // Same feature up to ties: the feature reported is at the brute-force minimum distance,
    // and a face feature is reported only when the closest point is inside that face.
    bool faceInterior = true;
    ASSERT_NEAR(featureDistance(mesh, topology, c.feature, p, &faceInterior), expected, tol)
        << "point " << i << ": " << clod::featureTypeName(c.feature.type) << " " << c.feature.index;
    if (expected > tol) {
      ASSERT_TRUE(faceInterior) << "point " << i << ": face reported for a boundary point";
    }
    // Normal: the independently computed (pseudo)normal of that feature.
    Vec3 normal;
    if (c.feature.type == FeatureType::kFace) {
      normal = normals.face[c.feature.index];
    } else if (c.feature.type == FeatureType::kVertex) {
      normal = normals.vertex[c.feature.index];
    } else {
      const clod::Edge e = topology.edges()[c.feature.index];
      normal = normals.edge.at({e.v0, e.v1});
    }
    ASSERT_NEAR((c.normal - normal).norm(), 0.0, 1e-9)
        << "point " << i << ": " << clod::featureTypeName(c.feature.type) << " " << c.feature.index << " normal "
        << c.normal.transpose() << " expected " << normal.transpose();
    EXPECT_TRUE(c.normal.allFinite());

    // Map the oracle's triangle-local feature to a mesh feature and count agreement.
    const auto& h = reference[i].hit;
    const std::uint32_t t = reference[i].triangle;
    clod::MeshFeature ref{h.type, t};
    if (h.type == FeatureType::kVertex) ref.index = mesh.triangles[t][h.local];
    if (h.type == FeatureType::kEdge) ref.index = topology.triangleEdge(t, h.local);
    if (ref.type == c.feature.type && ref.index == c.feature.index) ++sameFeature;
  }
  // Ties (two features at the same distance) are rare for random points; a systematic
  // misclassification would show up as far more disagreement than this.
  EXPECT_GE(sameFeature, int(points.size() * 0.98)) << "of " << points.size();
}

// ---- signs and winding numbers ---------------------------------------------------------------

TEST_P(MeshDistanceOnCorpus, SignMethodIsPseudonormalExactlyForClosedOrientedMeshes) {
  const MeshDistance& md = meshDistance(GetParam().name);
  const std::string& name = GetParam().name;
  if (name == "cow.obj") {
    // Closed edges but pinched (non-manifold) vertices: pseudonormals are not trustworthy there.
    EXPECT_TRUE(md.topology().closed());
    EXPECT_EQ(md.signMethod(), SignMethod::kWindingNumber);
  } else {
    EXPECT_EQ(md.signMethod(), GetParam().closed ? SignMethod::kPseudonormal : SignMethod::kWindingNumber);
  }
  EXPECT_EQ(meshDistance(name, true).signMethod(), SignMethod::kWindingNumber);
}

TEST_P(MeshDistanceOnCorpus, HierarchicalWindingNumberMatchesExactSum) {
  const TriangleMesh& mesh = testMesh(GetParam().name);
  const MeshDistance& md = meshDistance(GetParam().name);
  const auto points = samplePoints(mesh, scaled(1000, 100), scaled(200, 20), 99);
  std::vector<double> exact(points.size());
  tbb::parallel_for(std::size_t(0), points.size(), [&](std::size_t i) { exact[i] = oracle::windingNumber(mesh, points[i]); });
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double w = md.windingNumber(points[i]);
    ASSERT_TRUE(std::isfinite(w));
    // Second-order far field at beta = 2 (Barill et al. 2018): each cluster's truncation error
    // is O(beta^-3) = 1/8 of its own (bounded) solid angle; measured worst over the corpus is
    // ~0.05. 0.1 keeps a margin of 4x to the 0.5 that separates inside from outside, so the
    // decision below is what this test is really about.
    ASSERT_NEAR(w, exact[i], 0.1) << "point " << i << " " << points[i].transpose();
    if (std::abs(exact[i] - 0.5) > 0.1) {
      ASSERT_EQ(w >= 0.5, exact[i] >= 0.5) << "point " << i << " " << points[i].transpose();
    }
  }
}

// The far-field expansion is second order, so its error must fall like beta^-3: from beta 2
// to 8 by ~64x. A first-order (dipole-only) or wrong second-order term falls at most 16x.
TEST(MeshDistanceWinding, ErrorFallsLikeBetaCubed) {
  for (const char* name : {"icosphere", "bunny-1500.obj"}) {
    const TriangleMesh& mesh = testMesh(name);
    const auto points = samplePoints(mesh, scaled(300, 60), 0, 17);
    std::vector<double> exact;
    for (const Vec3& p : points) exact.push_back(oracle::windingNumber(mesh, p));
    auto meanError = [&](double beta) {
      clod::MeshDistanceSettings settings;
      settings.windingBeta = beta;
      const MeshDistance md(mesh, settings);
      double sum = 0.0;
      for (std::size_t i = 0; i < points.size(); ++i) sum += std::abs(md.windingNumber(points[i]) - exact[i]);
      return sum / points.size();
    };
    const double coarse = meanError(2.0), fine = meanError(8.0);
    EXPECT_GT(coarse, 0.0) << name;
    EXPECT_LT(fine, coarse / 20.0) << name << ": beta 2 -> " << coarse << ", beta 8 -> " << fine;
  }
}

TEST_P(MeshDistanceOnCorpus, SignAgreesWithRayParityOnClosedMeshes) {
  if (!GetParam().closed) GTEST_SKIP() << "ray parity needs a closed mesh";
  const TriangleMesh& mesh = testMesh(GetParam().name);
  const MeshDistance& md = meshDistance(GetParam().name);
  const double diagonal = mesh.bounds().diagonal();
  const auto points = samplePoints(mesh, scaled(1000, 100), scaled(500, 50), 4321);
  std::vector<int> inside(points.size());
  tbb::parallel_for(std::size_t(0), points.size(), [&](std::size_t i) {
    std::mt19937_64 rng(i);
    inside[i] = oracle::insideByRayParity(mesh, points[i], rng);
  });
  int checked = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (inside[i] < 0) continue;
    const auto s = md.signedQuery(points[i]);
    // Points within 1e-9 of the diagonal of the surface: the parity ray's own rounding can
    // decide either way there, so they test nothing.
    if (s.closest.distance < 1e-9 * diagonal) continue;
    ++checked;
    ASSERT_EQ(s.signedDistance < 0, inside[i] == 1) << "point " << i << " " << points[i].transpose()
                                                    << " d=" << s.signedDistance;
    ASSERT_EQ(std::abs(s.signedDistance), s.closest.distance);
    // Closed meshes: the exact winding number is 0 or 1 away from the surface.
    if (i % 10 == 0) {
      ASSERT_NEAR(oracle::windingNumber(mesh, points[i]), inside[i], 1e-6) << "point " << i;
    }
  }
  EXPECT_GT(checked, int(points.size() * 0.9));
}

TEST_P(MeshDistanceOnCorpus, PseudonormalSignAgreesWithWindingNumberAwayFromTheSurface) {
  if (!GetParam().closed) GTEST_SKIP() << "pseudonormal signs are defined for closed meshes";
  const TriangleMesh& mesh = testMesh(GetParam().name);
  const MeshDistance& byNormal = meshDistance(GetParam().name);
  const MeshDistance& byWinding = meshDistance(GetParam().name, true);
  const double diagonal = mesh.bounds().diagonal();
  const auto points = samplePoints(mesh, scaled(10000, 500), scaled(2000, 100), 777);
  int compared = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto a = byNormal.signedQuery(points[i]);
    if (a.closest.distance < 1e-4 * diagonal) continue;  // "away from the surface"
    ++compared;
    const double b = byWinding.signedDistance(points[i]);
    ASSERT_EQ(a.signedDistance, b) << "point " << i << " " << points[i].transpose();
  }
  EXPECT_GT(compared, int(points.size() * 0.8));
}

TEST_P(MeshDistanceOnCorpus, ConcurrentQueriesGiveTheSerialAnswers) {
  const TriangleMesh& mesh = testMesh(GetParam().name);
  const MeshDistance& md = meshDistance(GetParam().name);
  const auto points = samplePoints(mesh, scaled(2000, 100), 0, 55);
  std::vector<double> parallel(points.size());
  tbb::parallel_for(std::size_t(0), points.size(), [&](std::size_t i) { parallel[i] = md.signedDistance(points[i]); });
  for (std::size_t i = 0; i < points.size(); ++i) ASSERT_EQ(parallel[i], md.signedDistance(points[i]));
}

INSTANTIATE_TEST_SUITE_P(Corpus, MeshDistanceOnCorpus, ::testing::ValuesIn(meshNames()), paramName);

// ---- analytic primitives -----------------------------------------------------------------

TEST(MeshDistanceAnalytic, BoxSignedDistanceIsTheExactBoxSdf) {
  const Vec3 h(1.0, 0.5, 2.0);
  const MeshDistance& md = meshDistance("box");
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int i = 0; i < scaled(20000, 2000); ++i) {
    const Vec3 p(u(rng), u(rng), u(rng));
    // Analytic box SDF: outside part |max(q, 0)| plus inside part min(max component of q, 0).
    const Vec3 q = p.cwiseAbs() - h;
    const double sdf = q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    ASSERT_NEAR(md.signedDistance(p), sdf, 1e-12) << p.transpose();
  }
}

TEST(MeshDistanceAnalytic, IcosphereSignedDistanceMatchesConvexPolyhedronFormula) {
  const TriangleMesh& mesh = testMesh("icosphere");
  const MeshDistance& md = meshDistance("icosphere");
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-2.5, 2.5);
  for (int i = 0; i < scaled(5000, 500); ++i) {
    const Vec3 p(u(rng), u(rng), u(rng));
    // Convex polyhedron: inside iff behind every face plane, and then the distance is the
    // smallest distance to a face plane.
    double maxPlane = -std::numeric_limits<double>::infinity();
    for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) {
      maxPlane = std::max(maxPlane, (p - mesh.corner(t, 0)).dot(mesh.triangleNormal(t)));
    }
    const double d = md.signedDistance(p);
    if (maxPlane < 0) {
      ASSERT_NEAR(d, maxPlane, 1e-12) << p.transpose();
    } else {
      ASSERT_GT(d, 0.0) << p.transpose();
    }
  }
}

TEST(MeshDistanceAnalytic, WindingNumberOfAClosedMeshIsOneInsideAndZeroOutside) {
  // beta = 32: truncation error ~32^-3 of a full turn at worst, i.e. < 1e-4.
  clod::MeshDistanceSettings settings;
  settings.windingBeta = 32.0;
  const MeshDistance md(testMesh("icosphere"), settings);
  EXPECT_NEAR(md.windingNumber(Vec3(0.1, -0.2, 0.3)), 1.0, 1e-4);
  EXPECT_NEAR(md.windingNumber(Vec3::Zero()), 1.0, 1e-4);
  EXPECT_NEAR(md.windingNumber(Vec3(10, 0, 0)), 0.0, 1e-4);
  EXPECT_NEAR(md.windingNumber(Vec3(1e6, -1e6, 0)), 0.0, 1e-9);
}

TEST(MeshDistanceAnalytic, OpenHalfSphereHasWindingNumberOneHalfAtItsCentre) {
  // Keep only the triangles of the upper half of an icosphere: seen from the centre, they
  // cover (about) half the sphere of directions.
  const TriangleMesh sphere = clod::makeIcosphere(1.0, 3);
  TriangleMesh half;
  half.vertices = sphere.vertices;
  for (std::uint32_t t = 0; t < sphere.triangleCount(); ++t) {
    const Vec3 c = (sphere.corner(t, 0) + sphere.corner(t, 1) + sphere.corner(t, 2)) / 3.0;
    if (c.z() > 0) half.triangles.push_back(sphere.triangles[t]);
  }
  const double exact = oracle::windingNumber(half, Vec3::Zero());
  clod::MeshDistanceSettings settings;
  settings.windingBeta = 32.0;
  const MeshDistance md(half, settings);
  EXPECT_EQ(md.signMethod(), SignMethod::kWindingNumber);
  EXPECT_NEAR(md.windingNumber(Vec3::Zero()), exact, 1e-4);
  // The zig-zag equator of the icosphere makes the covered fraction only roughly 1/2.
  EXPECT_NEAR(exact, 0.5, 0.05);
}

// ---- degenerate input and bad meshes -----------------------------------------------------

TEST(MeshDistanceDegenerate, DegenerateTrianglesNeverGiveNaN) {
  const MeshDistance& md = meshDistance("degenerate");
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-2, 2);
  std::vector<Vec3> points;
  for (const Vec3& v : md.mesh().vertices) points.push_back(v);  // exactly on the degenerate corners
  for (int i = 0; i < 2000; ++i) points.emplace_back(u(rng), u(rng), u(rng));
  for (const Vec3& p : points) {
    const auto s = md.signedQuery(p);
    ASSERT_TRUE(std::isfinite(s.signedDistance)) << p.transpose();
    ASSERT_TRUE(s.closest.point.allFinite() && s.closest.normal.allFinite()) << p.transpose();
    ASSERT_TRUE(std::isfinite(md.windingNumber(p)));
  }
}

TEST(MeshDistanceErrors, RejectsMeshesWithoutUsableTriangles) {
  auto codeOf = [](TriangleMesh m) {
    try {
      MeshDistance md(std::move(m));
    } catch (const clod::Error& e) {
      return e.code();
    }
    return clod::ErrorCode::kInvalidArgument;
  };
  TriangleMesh empty;
  EXPECT_EQ(codeOf(empty), clod::ErrorCode::kNoTriangles);
  TriangleMesh outOfRange{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, {{0, 1, 3}}};
  EXPECT_EQ(codeOf(outOfRange), clod::ErrorCode::kIndexOutOfRange);
  TriangleMesh nan{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, std::nan(""), 0)}, {{0, 1, 2}}};
  EXPECT_EQ(codeOf(nan), clod::ErrorCode::kNonFiniteVertex);
  TriangleMesh flat{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)}, {{0, 1, 2}}};
  EXPECT_EQ(codeOf(flat), clod::ErrorCode::kAllTrianglesDegenerate);
}

TEST(MeshDistanceErrors, OutOfRangeMessageNamesTheTriangle) {
  TriangleMesh m{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, {{0, 1, 2}, {0, 2, 9001}}};
  try {
    MeshDistance md(std::move(m));
    FAIL();
  } catch (const clod::Error& e) {
    EXPECT_NE(std::string(e.what()).find("triangle 1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("9001"), std::string::npos) << e.what();
  }
}

TEST(MeshDistanceSubset, ClosestPointAmongMatchesBruteForceOverTheSubset) {
  const TriangleMesh& mesh = testMesh("spot.obj");
  const MeshDistance& md = meshDistance("spot.obj");
  std::vector<std::uint32_t> subset;
  for (std::uint32_t t = 0; t < mesh.triangleCount(); t += 7) subset.push_back(t);
  TriangleMesh sub;
  sub.vertices = mesh.vertices;
  for (std::uint32_t t : subset) sub.triangles.push_back(mesh.triangles[t]);
  const auto points = samplePoints(mesh, 300, 100, 8);
  for (const Vec3& p : points) {
    const auto c = md.closestPointAmong(p, subset);
    const auto ref = oracle::closestOnMesh(sub, p);
    ASSERT_NEAR(c.distance, ref.hit.distance, 1e-12);
  }
}

TEST(MeshDistanceSettingsCheck, OutOfRangeSettingsAreInvalidArguments) {
  for (int which = 0; which < 3; ++which) {
    clod::MeshDistanceSettings settings;
    if (which == 0) settings.leafSize = 0;
    if (which == 1) settings.windingBeta = 0.5;
    if (which == 2) settings.windingBeta = std::nan("");
    try {
      MeshDistance md(clod::makeBox(Vec3::Ones()), settings);
      ADD_FAILURE() << "setting " << which << " accepted";
    } catch (const clod::Error& e) {
      EXPECT_EQ(e.code(), clod::ErrorCode::kInvalidArgument);
    }
  }
}

TEST(MeshDistanceSettingsCheck, EveryLeafSizeGivesTheSameDistances) {
  const TriangleMesh& mesh = testMesh("fandisk.obj");
  const auto points = samplePoints(mesh, scaled(500, 50), scaled(200, 20), 9);
  const MeshDistance& reference = meshDistance("fandisk.obj");
  for (std::uint32_t leaf : {1u, 2u, 8u, 16u}) {
    clod::MeshDistanceSettings settings;
    settings.leafSize = leaf;
    const MeshDistance md(mesh, settings);
    for (const Vec3& p : points) ASSERT_EQ(md.closestPoint(p).distance, reference.closestPoint(p).distance);
  }
}

}  // namespace

namespace clod {
namespace {

// A sheet (an open mesh that encloses nothing: a floor quad, a terrain) signed by its
// pseudonormals with MeshDistanceSettings::sheetPseudonormals: behind it is inside, beyond its
// border outside. Oracle: the analytic distance to the plane over the footprint, signed by the
// side; beyond it the distance to the rectangle. Long thin triangles (a
// 13.7 x 3 m quad in two) included: a box on such a floor read -0.669 at 0.669 above it.
TEST(MeshDistanceSheet, QuadIsSignedByItsSideOverItsFootprint) {
  for (double hx : {1.0, 6.86}) {
    const double hy = 1.5, z = 0.25;
    const TriangleMesh quad = test::makeFloorQuad(hx, hy, z);
    const MeshDistance winding(quad);
    EXPECT_EQ(winding.signMethod(), SignMethod::kWindingNumber);
    const MeshDistance sheet(quad, MeshDistanceSettings{.sheetPseudonormals = true});
    ASSERT_EQ(sheet.signMethod(), SignMethod::kPseudonormal);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-0.95, 0.95), h(-1.0, 1.0);
    for (int i = 0; i < 2000; ++i) {
      const Vec3 p(u(rng) * hx, u(rng) * hy, z + h(rng));
      // 1e-12 of the quad's size: rounding of the closest point.
      EXPECT_NEAR(sheet.signedDistance(p), p.z() - z, 1e-12 * hx) << p.transpose();
    }
    // Beyond the border the solid behind the sheet ends: outside, at the distance to the quad
    // (oracle: the point's offset from the rectangle, clamped per axis), under the plane too.
    for (int i = 0; i < 2000; ++i) {
      const Vec3 p(u(rng) * 2.0 * hx, u(rng) * 2.0 * hy, z + h(rng));
      const Vec3 beyond(std::max(std::abs(p.x()) - hx, 0.0), std::max(std::abs(p.y()) - hy, 0.0), p.z() - z);
      if (beyond.x() == 0.0 && beyond.y() == 0.0) continue;  // over the footprint: above
      EXPECT_NEAR(sheet.signedDistance(p), beyond.norm(), 1e-12 * hx) << p.transpose();
    }
  }
}

}  // namespace
}  // namespace clod
