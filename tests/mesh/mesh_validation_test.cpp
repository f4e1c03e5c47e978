#include "clod/mesh_validation.h"

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "clod/primitives.h"
#include "mesh_test_support.h"

namespace clod {
namespace {

TriangleMesh singleTriangle() {
  TriangleMesh mesh;
  mesh.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  mesh.triangles = {{0, 1, 2}};
  return mesh;
}

// Tetrahedron with corners at `offset` + {0, x, y, z}, outward.
void appendTetrahedron(TriangleMesh& mesh, const Vec3& offset) {
  const std::uint32_t b = mesh.vertexCount();
  mesh.vertices.insert(mesh.vertices.end(), {offset, offset + Vec3(1, 0, 0), offset + Vec3(0, 1, 0), offset + Vec3(0, 0, 1)});
  mesh.triangles.insert(mesh.triangles.end(), {{b, b + 2, b + 1}, {b, b + 1, b + 3}, {b, b + 3, b + 2}, {b + 1, b + 2, b + 3}});
}

std::size_t countFatal(const MeshReport& report) {
  std::size_t n = 0;
  for (const MeshIssue& issue : report.issues) n += issue.fatal.has_value();
  return n;
}

ErrorCode thrownCode(const TriangleMesh& mesh, std::string* message = nullptr) {
  try {
    requireValidMesh(mesh);
  } catch (const Error& e) {
    if (message) *message = e.what();
    return e.code();
  }
  ADD_FAILURE() << "requireValidMesh did not throw";
  return ErrorCode::kInvalidArgument;
}

TEST(ValidateMesh, SingleTriangleIsOpenWithThreeBoundaryEdges) {
  const MeshReport r = validateMesh(singleTriangle());
  EXPECT_TRUE(r.usable());
  EXPECT_EQ(r.vertexCount, 3u);
  EXPECT_EQ(r.triangleCount, 1u);
  EXPECT_EQ(r.boundaryEdges, 3u);
  EXPECT_EQ(r.nonManifoldEdges, 0u);
  EXPECT_FALSE(r.closed);
  EXPECT_TRUE(r.consistentlyOriented);
  EXPECT_EQ(r.components, 1u);
  EXPECT_FALSE(r.signedVolume.has_value());
  EXPECT_EQ(r.bounds.min, Vec3(0, 0, 0));
  EXPECT_EQ(r.bounds.max, Vec3(1, 1, 0));
}

TEST(ValidateMesh, BoxIsClosedWithItsExactVolume) {
  const Vec3 half(0.5, 1.0, 1.5);
  const MeshReport r = validateMesh(makeBox(half));
  EXPECT_TRUE(r.usable());
  EXPECT_TRUE(r.closed);
  EXPECT_TRUE(r.consistentlyOriented);
  EXPECT_EQ(r.edgeCount, 18u);
  EXPECT_EQ(r.components, 1u);
  EXPECT_TRUE(r.issues.empty());
  ASSERT_TRUE(r.signedVolume.has_value());
  // 8 * 0.5 * 1 * 1.5 = 6; the terms are small integers and halves, exact in binary.
  EXPECT_DOUBLE_EQ(*r.signedVolume, 6.0);
  EXPECT_FALSE(r.insideOut());
}

TEST(ValidateMesh, FlippedBoxIsInsideOutWithNegativeVolume) {
  TriangleMesh box = makeBox(Vec3(1, 1, 1));
  flipOrientation(box);
  const MeshReport r = validateMesh(box);
  EXPECT_TRUE(r.usable());
  ASSERT_TRUE(r.signedVolume.has_value());
  EXPECT_DOUBLE_EQ(*r.signedVolume, -8.0);
  EXPECT_TRUE(r.insideOut());
  EXPECT_FALSE(r.issues.empty());
}

TEST(ValidateMesh, OneFlippedTriangleMakesThreeEdgesInconsistent) {
  TriangleMesh box = makeBox(Vec3(1, 1, 1));
  std::swap(box.triangles[5][1], box.triangles[5][2]);
  const MeshReport r = validateMesh(box);
  EXPECT_TRUE(r.closed);
  EXPECT_FALSE(r.consistentlyOriented);
  EXPECT_EQ(r.inconsistentEdges, 3u);
  EXPECT_FALSE(r.signedVolume.has_value());
}

TEST(ValidateMesh, TwoDisjointBoxesAreTwoComponents) {
  TriangleMesh mesh = makeBox(Vec3(1, 1, 1));
  const TriangleMesh other = makeBox(Vec3(1, 1, 1));
  const std::uint32_t base = mesh.vertexCount();
  for (const Vec3& v : other.vertices) mesh.vertices.push_back(v + Vec3(5, 0, 0));
  for (const Triangle& t : other.triangles) mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  const MeshReport r = validateMesh(mesh);
  EXPECT_EQ(r.components, 2u);
  EXPECT_TRUE(r.closed);
  ASSERT_TRUE(r.signedVolume.has_value());
  EXPECT_DOUBLE_EQ(*r.signedVolume, 16.0);
}

TEST(ValidateMesh, ThreeTrianglesOnOneEdgeMakeItNonManifold) {
  TriangleMesh mesh;
  mesh.vertices = {Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(-1, -1, 0)};
  mesh.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  const MeshReport r = validateMesh(mesh);
  EXPECT_EQ(r.nonManifoldEdges, 1u);
  EXPECT_EQ(r.boundaryEdges, 6u);
  EXPECT_FALSE(r.closed);
  EXPECT_TRUE(r.usable());
}

TEST(ValidateMesh, TetrahedraTouchingAtAVertexMakeItNonManifold) {
  TriangleMesh mesh;
  appendTetrahedron(mesh, Vec3(0, 0, 0));
  appendTetrahedron(mesh, Vec3(-1, 0, 0));  // its corner +x is the first one's origin
  // Weld the shared corner by hand: vertex 5 (= (0,0,0)) becomes vertex 0.
  for (Triangle& t : mesh.triangles)
    for (auto& i : t)
      if (i == 5) i = 0;
  const MeshReport r = validateMesh(mesh);
  EXPECT_TRUE(r.closed);  // every edge still has two triangles
  EXPECT_EQ(r.nonManifoldVertices, 1u);
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(r.unreferencedVertices, 1u);  // the old vertex 5
  ASSERT_TRUE(r.signedVolume.has_value());
  EXPECT_NEAR(*r.signedVolume, 2.0 / 6.0, 1e-15);
}

TEST(ValidateMesh, DuplicateAndDegenerateTrianglesAreCountedNotFatal) {
  TriangleMesh mesh = makeBox(Vec3(1, 1, 1));
  mesh.triangles.push_back({mesh.triangles[0][0], mesh.triangles[0][2], mesh.triangles[0][1]});  // reversed copy
  // A collinear triangle: vertices 0, 1 and the midpoint of the edge 0-1.
  mesh.vertices.push_back(0.5 * (mesh.vertices[0] + mesh.vertices[1]));
  mesh.triangles.push_back({0, 1, mesh.vertexCount() - 1});
  mesh.triangles.push_back({2, 2, 3});  // repeated corner
  const MeshReport r = validateMesh(mesh);
  EXPECT_TRUE(r.usable());
  EXPECT_EQ(r.duplicateTriangles, 1u);
  EXPECT_EQ(r.degenerateTriangles, 2u);
  EXPECT_FALSE(r.closed);
}

TEST(ValidateMesh, ReportsEveryFatalIssueAndThrowsTheFirst) {
  TriangleMesh mesh = singleTriangle();
  mesh.vertices.push_back(Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0));
  mesh.vertices.push_back(Vec3(0, std::numeric_limits<double>::infinity(), 0));
  mesh.triangles.push_back({0, 1, 9001});
  mesh.triangles.push_back({0, 7, 2});
  const MeshReport r = validateMesh(mesh);
  EXPECT_FALSE(r.usable());
  EXPECT_EQ(r.nonFiniteVertices, 2u);
  EXPECT_EQ(r.outOfRangeTriangles, 2u);
  EXPECT_EQ(countFatal(r), 4u);
  std::string message;
  EXPECT_EQ(thrownCode(mesh, &message), ErrorCode::kNonFiniteVertex);
  EXPECT_NE(message.find("vertex 3"), std::string::npos) << message;
  EXPECT_NE(message.find("3 more"), std::string::npos) << message;
}

TEST(ValidateMesh, OutOfRangeIndexNamesTriangleAndIndex) {
  TriangleMesh mesh = singleTriangle();
  mesh.triangles.push_back({0, 2, 9001});
  std::string message;
  EXPECT_EQ(thrownCode(mesh, &message), ErrorCode::kIndexOutOfRange);
  EXPECT_EQ(message, "triangle 1: vertex index 9001 >= vertex count 3");
}

TEST(ValidateMesh, NoTrianglesIsFatal) {
  TriangleMesh mesh = singleTriangle();
  mesh.triangles.clear();
  EXPECT_EQ(thrownCode(mesh), ErrorCode::kNoTriangles);
  EXPECT_EQ(thrownCode(TriangleMesh{}), ErrorCode::kNoTriangles);
}

TEST(ValidateMesh, AllTrianglesDegenerateIsFatal) {
  TriangleMesh mesh;
  mesh.vertices = {Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2), Vec3(0.3, 0.3, 0.3)};
  mesh.triangles = {{0, 1, 2}, {1, 2, 3}, {0, 0, 1}};
  EXPECT_EQ(thrownCode(mesh), ErrorCode::kAllTrianglesDegenerate);
}

// Boxes scaled so that their diagonal lies just inside and just outside [kMinMeshDiagonal,
// kMaxMeshDiagonal]: inside they are valid closed boxes, outside the size is the fatal finding
// (a 1e200 box's sphere-tree radius overflowed to infinity, a 1e-300 sphere's triangles read as
// zero-area). Oracle: the box's diagonal, 2 sqrt(3) times its half extent.
TEST(ValidateMesh, SizesOutsideTheSupportedRangeAreFatal) {
  const double unitDiagonal = 2.0 * std::sqrt(3.0);
  for (double diagonal : {1.01 * kMinMeshDiagonal, 0.99 * kMaxMeshDiagonal}) {
    const MeshReport report = validateMesh(makeBox(Vec3::Constant(diagonal / unitDiagonal)));
    EXPECT_TRUE(report.usable()) << diagonal;
    EXPECT_TRUE(report.closed) << diagonal;
  }
  for (double diagonal : {0.99 * kMinMeshDiagonal, 1.01 * kMaxMeshDiagonal, 1e-300, 1e300}) {
    std::string message;
    EXPECT_EQ(thrownCode(makeBox(Vec3::Constant(diagonal / unitDiagonal)), &message), ErrorCode::kUnsupportedMesh) << diagonal;
    EXPECT_NE(message.find("outside the supported range"), std::string::npos) << message;
  }
}

TEST(ValidateMesh, FlatSquareLoadsAsOpenNotFatal) {
  TriangleMesh mesh;
  mesh.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  const MeshReport r = requireValidMesh(mesh);
  EXPECT_EQ(r.boundaryEdges, 4u);
  EXPECT_EQ(r.degenerateTriangles, 0u);
  bool flatWarning = false;
  for (const MeshIssue& issue : r.issues) flatWarning |= issue.message == "the mesh is flat: zero extent along z";
  EXPECT_TRUE(flatWarning);
}

// Random small meshes over a tiny vertex pool produce every kind of topological defect at once;
// each count is compared with a brute-force computation from mesh_test_support.h.
TEST(ValidateMesh, CountsMatchBruteForceOnRandomSoups) {
  std::mt19937 rng(42);
  const int rounds = test::sanitizerRun() ? 100 : 500;
  for (int round = 0; round < rounds; ++round) {
    TriangleMesh mesh;
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    const std::uint32_t poolSize = 5 + round % 8;
    for (std::uint32_t v = 0; v < poolSize; ++v) mesh.vertices.emplace_back(unit(rng), unit(rng), unit(rng));
    std::uniform_int_distribution<std::uint32_t> pick(0, poolSize - 1);
    const int triangleCount = 1 + round % 20;
    for (int t = 0; t < triangleCount; ++t) {
      std::uint32_t a = pick(rng), b = pick(rng), c = pick(rng);
      while (b == a) b = pick(rng);
      while (c == a || c == b) c = pick(rng);
      mesh.triangles.push_back({a, b, c});
    }
    const MeshReport r = validateMesh(mesh);

    std::uint32_t boundary = 0, nonManifold = 0;
    const auto uses = test::countEdgeUses(mesh);
    for (const auto& [edge, count] : uses) {
      boundary += count == 1;
      nonManifold += count > 2;
    }
    std::uint32_t inconsistent = 0;
    for (const auto& [edge, count] : uses) {
      if (count != 2) continue;
      int forward = 0;  // sides running first -> second
      for (const Triangle& t : mesh.triangles)
        for (int k = 0; k < 3; ++k) forward += t[k] == edge.first && t[(k + 1) % 3] == edge.second;
      inconsistent += forward != 1;
    }
    std::uint32_t duplicates = 0;
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
      for (std::size_t j = 0; j < i; ++j) {
        Triangle a = mesh.triangles[i], b = mesh.triangles[j];
        std::sort(a.begin(), a.end());
        std::sort(b.begin(), b.end());
        if (a == b) {
          ++duplicates;
          break;
        }
      }
    // Non-manifold vertices: incident triangles joined when they share an edge through the vertex.
    std::uint32_t nonManifoldVertices = 0, unreferenced = 0;
    for (std::uint32_t v = 0; v < poolSize; ++v) {
      std::vector<std::size_t> incident;
      for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
        if (std::count(mesh.triangles[t].begin(), mesh.triangles[t].end(), v)) incident.push_back(t);
      if (incident.empty()) {
        ++unreferenced;
        continue;
      }
      auto shareEdgeThrough = [&](std::size_t s, std::size_t t) {
        int shared = 0;
        for (std::uint32_t w : mesh.triangles[s])
          if (w != v && std::count(mesh.triangles[t].begin(), mesh.triangles[t].end(), w)) ++shared;
        return shared > 0;
      };
      std::vector<int> group(incident.size(), -1);
      int groups = 0;
      for (std::size_t i = 0; i < incident.size(); ++i) {
        if (group[i] >= 0) continue;
        std::vector<std::size_t> stack{i};
        group[i] = groups;
        while (!stack.empty()) {
          std::size_t s = stack.back();
          stack.pop_back();
          for (std::size_t j = 0; j < incident.size(); ++j)
            if (group[j] < 0 && shareEdgeThrough(incident[s], incident[j])) {
              group[j] = groups;
              stack.push_back(j);
            }
        }
        ++groups;
      }
      nonManifoldVertices += groups > 1;
    }

    ASSERT_TRUE(r.usable()) << "round " << round;
    EXPECT_EQ(r.boundaryEdges, boundary) << "round " << round;
    EXPECT_EQ(r.nonManifoldEdges, nonManifold) << "round " << round;
    EXPECT_EQ(r.edgeCount, uses.size()) << "round " << round;
    EXPECT_EQ(r.inconsistentEdges, inconsistent) << "round " << round;
    EXPECT_EQ(r.duplicateTriangles, duplicates) << "round " << round;
    EXPECT_EQ(r.components, test::countComponentsByFloodFill(mesh)) << "round " << round;
    EXPECT_EQ(r.nonManifoldVertices, nonManifoldVertices) << "round " << round;
    EXPECT_EQ(r.unreferencedVertices, unreferenced) << "round " << round;
    EXPECT_EQ(r.closed, boundary == 0 && nonManifold == 0) << "round " << round;
  }
}

}  // namespace
}  // namespace clod
