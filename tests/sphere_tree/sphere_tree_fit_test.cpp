// The fit metric against analytic cases, and the required quality property: the medial builder
// fits tighter than the octree builder on every level below the root of every shared closed mesh.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "clod/error.h"
#include "clod/mesh_io.h"
#include "clod/primitives.h"
#include "clod/proximity.h"
#include "clod/sphere_tree_builder.h"
#include "sphere_tree_test_support.h"

namespace clod {
namespace {

// Every direction lies within this angle of one of N well-spread sample directions: a cap of
// angular radius acos(1 - 2/N) has area 4*pi/N, so N caps of that radius are the least that
// can cover the sphere; spherical Fibonacci sets cover within twice that radius.
double coveringAngle(std::uint32_t n) { return 2.0 * std::acos(1.0 - 2.0 / n); }

// A one-sphere tree (plain data, built by hand) responsible for every triangle of the mesh.
SphereTree singleSphereTree(const TriangleMesh& mesh, const Vec3& center, double radius) {
  SphereTree tree;
  tree.centerX = {center.x()};
  tree.centerY = {center.y()};
  tree.centerZ = {center.z()};
  tree.radius = {radius};
  tree.parent = {kNoSphere};
  tree.firstChild = {kNoSphere};
  tree.childCount = {0};
  tree.triangleOffsets = {0, mesh.triangleCount()};
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) tree.triangleList.push_back(t);
  tree.levelOffsets = {0, 1};
  return tree;
}

TEST(SphereTreeFit, CubeCircumsphereOvershootsByRadiusMinusHalfSizeAtTheFaceCentres) {
  // For a cube of half-size h, the circumsphere (radius R = h*sqrt(3)) is farthest from the cube
  // in the face-normal directions, where its overshoot is R - h; elsewhere it is less.
  const double h = 0.7;
  const MeshDistance cube(makeBox(Vec3::Constant(h)));
  const double diagonal = 2.0 * h * std::sqrt(3.0);
  const double radius = h * std::sqrt(3.0);
  SphereFitSettings settings;
  settings.samplesPerSphere = 4000;
  const auto fit = measureSphereTreeFit(singleSphereTree(cube.mesh(), Vec3::Zero(), radius), cube, settings);
  ASSERT_EQ(fit.size(), 1u);
  EXPECT_EQ(fit[0].spheres, 1u);
  // Upper bound: the true maximum. Lower bound: the nearest sample to a face direction is within
  // the covering angle theta, and there the distance to the cube is at least R cos(theta) - h
  // (the distance to the face plane).
  const double exact = (radius - h) / diagonal;
  const double lowest = (radius * std::cos(coveringAngle(settings.samplesPerSphere)) - h) / diagonal;
  EXPECT_LE(fit[0].fitMax, exact + 1e-12);
  EXPECT_GE(fit[0].fitMax, lowest);
  EXPECT_DOUBLE_EQ(fit[0].fitMean, fit[0].fitMax);
}

TEST(SphereTreeFit, BothBuildersMakeTheCubesRootItsCircumsphere) {
  // The smallest sphere around a cube is its circumsphere; the builders shrink the root to it.
  const double h = 1.3;
  const MeshDistance cube(makeBox(Vec3::Constant(h)));
  const double diagonal = 2.0 * h * std::sqrt(3.0);
  for (SphereTreeMethod method : {SphereTreeMethod::kOctree, SphereTreeMethod::kMedial}) {
    SphereTreeSettings settings;
    settings.method = method;
    settings.depth = 1;
    const SphereTree tree = buildSphereTree(cube, settings);
    // Allowed slack: the documented 1e-9 * diagonal inflation plus rounding.
    EXPECT_NEAR(tree.radius[0], h * std::sqrt(3.0), 2e-9 * diagonal) << sphereTreeMethodName(method);
    EXPECT_LE(tree.center(0).norm(), 1e-9 * diagonal) << sphereTreeMethodName(method);
  }
}

TEST(SphereTreeFit, IcosphereRootFitsWithinCircumradiusMinusInradius) {
  // Every point of the circumsphere is within R - r_in of the polyhedron: the ray from the centre
  // leaves the polyhedron at distance >= r_in (it contains its insphere). r_in is measured here
  // directly as the smallest distance from the centre to a face plane.
  const double radius = 2.0;
  const MeshDistance sphere(makeIcosphere(radius, 3));
  double inradius = radius;
  for (std::uint32_t t = 0; t < sphere.mesh().triangleCount(); ++t)
    inradius = std::min(inradius, std::abs(sphere.mesh().triangleNormal(t).dot(sphere.mesh().corner(t, 0))));
  const double diagonal = sphere.mesh().bounds().diagonal();
  SphereTreeSettings settings;
  settings.depth = 2;
  settings.medialSamples = 3000;
  const SphereTree tree = buildSphereTree(sphere, settings);
  const auto fit = measureSphereTreeFit(tree, sphere);
  ASSERT_EQ(fit.size(), 3u);
  EXPECT_LE(fit[0].fitMax, (radius - inradius) / diagonal + 2e-9);
  EXPECT_NEAR(tree.radius[0], radius, 2e-9 * diagonal);
}

TEST(SphereTreeFit, SphereOverAFlatSquareOvershootsByItsRadiusAtThePoles) {
  // A sphere of radius rho centred on a large flat square: the poles are rho from the plane, and
  // every other point of the sphere is nearer to it.
  TriangleMesh square;
  square.vertices = {Vec3(-5, -5, 0), Vec3(5, -5, 0), Vec3(5, 5, 0), Vec3(-5, 5, 0)};
  square.triangles = {{0, 1, 2}, {0, 2, 3}};
  const MeshDistance plane(square);
  const double rho = 1.25;
  SphereFitSettings settings;
  settings.samplesPerSphere = 1000;
  const auto fits = measureSphereFits(singleSphereTree(square, Vec3(0.5, -0.25, 0.0), rho), plane, settings);
  const double diagonal = square.bounds().diagonal();
  EXPECT_LE(fits[0], rho / diagonal + 1e-12);
  EXPECT_GE(fits[0], rho * std::cos(coveringAngle(settings.samplesPerSphere)) / diagonal);
}

TEST(SphereTreeFit, MalformedTreesAndSettingsThrowInvalidArgument) {
  const MeshDistance cube(makeBox(Vec3::Constant(1.0)));
  SphereTree tree = singleSphereTree(cube.mesh(), Vec3::Zero(), 2.0);
  tree.triangleList[3] = 99;
  try {
    measureSphereTreeFit(tree, cube);
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("99"), std::string::npos) << e.what();
  }
  tree = singleSphereTree(cube.mesh(), Vec3::Zero(), 2.0);
  tree.radius.push_back(1.0);
  EXPECT_THROW(measureSphereTreeFit(tree, cube), Error);
  SphereFitSettings settings;
  settings.samplesPerSphere = 0;
  EXPECT_THROW(measureSphereFits(singleSphereTree(cube.mesh(), Vec3::Zero(), 2.0), cube, settings), Error);
}

class ClosedMeshFit : public ::testing::TestWithParam<const char*> {};

TEST_P(ClosedMeshFit, MedialFitsTighterThanOctreeOnEveryLevelBelowTheRoot) {
  // Oracle: measureSphereTreeFit, which measures every sphere against the exact closest points
  // of its triangles (MeshDistance) and shares no code with either builder's own fit estimate.
  // Under sanitizers one mesh of each kind: fandisk (sharp CAD) and spot (smooth) take every code
  // path of both builders and of the fit measurement.
  const std::string name = GetParam();
  if (test::sanitizerRun() && name != "fandisk.obj" && name != "spot.obj") GTEST_SKIP() << "Release run only";
  const LoadedMesh loaded = loadMesh(std::filesystem::path(CLOD_SHARED_MESH_DIR) / name);
  const MeshDistance distance(loaded.mesh);
  SphereTreeSettings settings;  // 8-ary, 4 levels below the root, as in the issue
  SphereFitSettings fitSettings;
  if (test::sanitizerRun()) {
    settings.medialSamples = 3000;
    fitSettings.samplesPerSphere = 20;
  }
  settings.method = SphereTreeMethod::kOctree;
  const auto octree = measureSphereTreeFit(buildSphereTree(distance, settings), distance, fitSettings);
  settings.method = SphereTreeMethod::kMedial;  // default reduction: the better of merge/burst and k-means
  const auto medial = measureSphereTreeFit(buildSphereTree(distance, settings), distance, fitSettings);
  ASSERT_EQ(octree.size(), 5u);
  ASSERT_EQ(medial.size(), 5u);
  for (std::size_t l = 1; l < 5; ++l) {
    EXPECT_LT(medial[l].fitMean, octree[l].fitMean)
        << "level " << l << ": medial " << medial[l].spheres << " spheres, octree " << octree[l].spheres;
    // The issue asks for the mean at least and aims for the max too; with the default settings
    // the medial builder wins both on these meshes, so the full-scale run holds it to that.
    if (!test::sanitizerRun()) {
      EXPECT_LT(medial[l].fitMax, octree[l].fitMax) << "level " << l;
    }
  }
  if (test::sanitizerRun()) return;  // the default above already runs the merge/burst code
  // Bradshaw's merge/burst reduction on its own beats the octree on the mean fit of every level.
  // (Not on the max: alone it leaves a few loose spheres deep down, e.g. on spot's level 4;
  // docs/benchmarks/sphere_tree.md has the figures.)
  settings.medialReduction = MedialReduction::kMergeBurst;
  const auto mergeBurst = measureSphereTreeFit(buildSphereTree(distance, settings), distance, fitSettings);
  ASSERT_EQ(mergeBurst.size(), 5u);
  for (std::size_t l = 1; l < 5; ++l)
    EXPECT_LT(mergeBurst[l].fitMean, octree[l].fitMean) << "merge/burst, level " << l;
}

TEST(MedialReduction, MergeAndBurstGiveEachOfTwoDistantBoxesItsOwnSphere) {
  // Two unit boxes 10 apart, branching 2: the only sensible pair of children is one per box
  // (any other split makes a sphere span the gap). Oracle: the triangle index ranges of the
  // two boxes, known from how the mesh is assembled.
  TriangleMesh mesh = makeBox(Vec3::Constant(0.5));
  const std::uint32_t boxTriangles = mesh.triangleCount();
  const std::uint32_t boxVertices = mesh.vertexCount();
  const TriangleMesh second = makeBox(Vec3::Constant(0.5));
  for (const Vec3& v : second.vertices) mesh.vertices.push_back(v + Vec3(10.0, 0.0, 0.0));
  for (const auto& t : second.triangles)
    mesh.triangles.push_back({t[0] + boxVertices, t[1] + boxVertices, t[2] + boxVertices});
  const MeshDistance distance(mesh);
  SphereTreeSettings settings;
  settings.branching = 2;
  settings.depth = 1;
  settings.medialSamples = 2000;
  settings.medialReduction = MedialReduction::kMergeBurst;
  const SphereTree tree = buildSphereTree(distance, settings);
  ASSERT_EQ(tree.levelCount(), 2u);
  ASSERT_EQ(tree.levelEnd(1) - tree.levelBegin(1), 2u);
  for (std::uint32_t s = tree.levelBegin(1); s < tree.levelEnd(1); ++s) {
    const auto tris = tree.triangles(s);
    ASSERT_FALSE(tris.empty());
    const bool first = tris.front() < boxTriangles;
    for (std::uint32_t t : tris) EXPECT_EQ(t < boxTriangles, first) << "sphere " << s << " spans both boxes";
    // A unit box's smallest enclosing sphere has radius sqrt(3)/2; a sphere reaching into the
    // other box would need a radius of at least 4.5.
    EXPECT_LT(tree.radius[s], 1.0) << "sphere " << s;
  }
}

INSTANTIATE_TEST_SUITE_P(Corpus, ClosedMeshFit,
                         ::testing::Values("spot.obj", "fandisk.obj", "rocker-arm.obj", "cow.obj"),
                         test::meshParamName);

}  // namespace
}  // namespace clod
