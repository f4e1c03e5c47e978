#include "clod/thread_meshes.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "clod/error.h"
#include "clod/math.h"
#include "clod/mesh_validation.h"
#include "mesh_test_support.h"

namespace clod {
namespace {

using test::expectClosedOrientedGenus;

double radiusOf(const Vec3& v) { return std::hypot(v.x(), v.y()); }

// The ISO 68-1 numbers for M16 x 2, from the standard's formulas written out here (not through
// IsoThread): H = 0.866025 P, D1 = d - 1.082532 P, d2 = d - 0.649519 P.
TEST(ThreadMeshes, IsoProfileNumbersForM16x2) {
  const IsoThread m16{0.016, 0.002};
  EXPECT_NEAR(m16.fundamentalHeight(), 0.866025 * 0.002, 1e-9);
  EXPECT_NEAR(m16.minorDiameter(), 0.016 - 1.082532 * 0.002, 1e-9);  // 13.835 mm
  EXPECT_NEAR(m16.pitchDiameter(), 0.016 - 0.649519 * 0.002, 1e-9);  // 14.701 mm
  // At the pitch diameter the flank (groove) and the tooth are equally wide, P / 2: the profile
  // crosses the pitch radius half a pitch apart on the two flanks.
  const double rPitch = 0.5 * m16.pitchDiameter();
  const double pUp = 0.25 * 0.002 + (rPitch - 0.5 * m16.minorDiameter()) / std::tan(std::numbers::pi / 3);
  EXPECT_NEAR(m16.profileRadius(pUp), rPitch, 1e-12);
  EXPECT_NEAR(m16.profileRadius(pUp + 0.001), rPitch, 1e-12);
  // Flanks at 30 degrees to the radial plane: dr/dz = 1 / tan 30.
  const double slope = (m16.profileRadius(0.0008) - m16.profileRadius(0.0007)) / 0.0001;
  EXPECT_NEAR(slope, 1.0 / std::tan(std::numbers::pi / 6), 1e-6);
}

class ThreadMeshParts : public ::testing::Test {
protected:
  const NutBoltParts parts{};
  const std::vector<NamedMesh> meshes = nutBoltMeshes(parts);
  const TriangleMesh& bolt = meshes[0].mesh;
  const TriangleMesh& nut = meshes[1].mesh;
};

TEST_F(ThreadMeshParts, BoltAndNutAreClosedManifoldAndOutward) {
  ASSERT_EQ(meshes.size(), 2u);
  EXPECT_EQ(meshes[0].name, "bolt");
  EXPECT_EQ(meshes[1].name, "nut");
  expectClosedOrientedGenus(bolt, 0);
  expectClosedOrientedGenus(nut, 1);
  // Counts from the construction (thread_meshes.h): rows of helix samples, the step faces'
  // extra rows, the ramps and step faces.
  const std::uint32_t n = parts.segmentsPerTurn, tb = parts.boltTurns, tn = parts.nutTurns;
  EXPECT_EQ(bolt.vertexCount(), (4 * tb + 1) * n + 4 + 2 * (n + 1));
  EXPECT_EQ(bolt.triangleCount(), 8 * tb * n + 2 * 2 * n + 2 * (n + 4));
  EXPECT_EQ(nut.vertexCount(), (4 * tn + 1) * n + 4 + (tn + 1) * n + 1);
  EXPECT_EQ(nut.triangleCount(), 8 * tn * n + 2 * tn * n + 2 * 2 * n + 2 * 5);
  // Moderate sizes, so that the scenes' tests run in seconds.
  EXPECT_LT(bolt.triangleCount(), 3000u);
  EXPECT_LT(nut.triangleCount(), 2000u);
}

// The pitch and the helix measured from the vertices: the crest vertices of the bolt (radius =
// d / 2) at angle 0 come in pairs (crest start, crest end) one pitch apart; at angle 90 degrees
// the same rows are a quarter pitch higher (right-handed helix).
TEST_F(ThreadMeshParts, PitchAndHelixMeasuredFromVertices) {
  const double p = parts.thread.pitch, rMajor = 0.5 * parts.thread.majorDiameter;
  const double eps = 1e-12;  // coordinates are computed, not measured: rounding only
  std::vector<double> at0, at90;
  for (const Vec3& v : bolt.vertices) {
    if (std::abs(radiusOf(v) - rMajor) > eps) continue;
    if (std::abs(v.y()) < eps && v.x() > 0) at0.push_back(v.z());
    if (std::abs(v.x()) < eps && v.y() > 0) at90.push_back(v.z());
  }
  std::sort(at0.begin(), at0.end());
  std::sort(at90.begin(), at90.end());
  ASSERT_GE(at0.size(), 2u * parts.boltTurns);
  ASSERT_EQ(at0.size() % 2, 0u);
  for (std::size_t k = 0; k + 2 < at0.size(); ++k) EXPECT_NEAR(at0[k + 2] - at0[k], p, 1e-9 * p) << k;
  const double measuredPitch = (at0[at0.size() - 2] - at0[0]) / double(at0.size() / 2 - 1);
  EXPECT_NEAR(measuredPitch, 0.002, 1e-12);
  EXPECT_NEAR(at0[1] - at0[0], p / 8, 1e-9 * p);  // crest flat P / 8
  ASSERT_EQ(at90.size(), at0.size() - 2);          // the top step face's extra row is at angle 0 only
  for (std::size_t k = 0; k < at90.size(); ++k) EXPECT_NEAR(at90[k] - at0[k], p / 4, 1e-9 * p) << k;
}

TEST_F(ThreadMeshParts, MinorAndMajorDiameters) {
  const IsoThread& t = parts.thread;
  const double c = parts.radialClearance;
  double boltMin = 1e9, boltMax = 0, nutMin = 1e9, nutThreadMax = 0;
  for (const Vec3& v : bolt.vertices) {
    const double r = radiusOf(v);
    if (r > 1e-12) boltMin = std::min(boltMin, r);  // the ends' axis points are at r = 0
    boltMax = std::max(boltMax, r);
  }
  for (const Vec3& v : nut.vertices) {
    const double r = radiusOf(v);
    nutMin = std::min(nutMin, r);
    if (r < 0.5 * parts.acrossFlats - 1e-9) nutThreadMax = std::max(nutThreadMax, r);  // not the hexagon
  }
  EXPECT_NEAR(2 * boltMin, 0.016 - 1.082532 * 0.002, 1e-8);
  EXPECT_NEAR(2 * boltMax, 0.016, 1e-12);
  EXPECT_NEAR(2 * nutMin, t.minorDiameter() + 2 * c, 1e-12);
  EXPECT_NEAR(2 * nutThreadMax, 0.016 + 2 * c, 1e-12);
  // The hexagon: across flats at the side middles, corners at acrossFlats / cos 30.
  double hexMax = 0;
  for (const Vec3& v : nut.vertices) hexMax = std::max(hexMax, radiusOf(v));
  EXPECT_NEAR(hexMax, 0.5 * parts.acrossFlats / std::cos(std::numbers::pi / 6), 1e-12);
  // Heights: (turns + 1) pitches from z = 0.
  EXPECT_NEAR(bolt.bounds().max.z(), (parts.boltTurns + 1) * t.pitch, 1e-12);
  EXPECT_NEAR(nut.bounds().max.z(), (parts.nutTurns + 1) * t.pitch, 1e-12);
  EXPECT_NEAR(bolt.bounds().min.z(), 0.0, 1e-15);
}

// Volume against the smooth solid's, written out here: at every angle the part is `turns`
// pitches long, so (Cavalieri) the rod's volume is turns x pi x integral of r(u)^2 over a pitch,
// r(u) the trapezoid profile, integrated numerically here (midpoint rule, 20,000 steps: error
// ~1e-9 relative). The mesh's facets are chords of the circles through its vertices: a polygon
// of n sides has n sin(2 pi / n) / (2 pi) of the circle's area, 1.1 % less at n = 24. The flank
// quads are not quite flat (their two triangles fold by < 1 degree) and the ramps are helicoids
// cut into triangles, which moves the volume by a further ~0.1 %, so the tolerance is 0.3 %
// of the polygonal volume (a profile off by one flat -- P / 8 of crest -- moves it by 2 %).
TEST_F(ThreadMeshParts, VolumeMatchesTheSmoothThreadTimesThePolygonFactor) {
  const double p = 0.002, rMinor = 0.5 * (0.016 - 1.082532 * 0.002), rMajor = 0.008;
  auto r = [&](double u) {
    const double x = u / p;
    if (x < 0.25) return rMinor;
    if (x < 0.5625) return rMinor + (rMajor - rMinor) * (x - 0.25) / 0.3125;
    if (x < 0.6875) return rMajor;
    return rMajor - (rMajor - rMinor) * (x - 0.6875) / 0.3125;
  };
  auto integralR2 = [&](double offset) {
    const int steps = 20000;
    double sum = 0;
    for (int i = 0; i < steps; ++i) {
      const double rr = r((i + 0.5) * p / steps) + offset;
      sum += rr * rr;
    }
    return sum * p / steps;
  };
  const double n = parts.segmentsPerTurn;
  const double polygon = n * std::sin(2 * std::numbers::pi / n) / (2 * std::numbers::pi);
  const double boltSmooth = parts.boltTurns * std::numbers::pi * integralR2(0.0);
  // 1e-6: the 7-digit constant 1.082532 for 5 sqrt(3) / 8 moves the minor radius by 2e-10 m.
  EXPECT_NEAR(parts.thread.solidVolumePerPitch() * parts.boltTurns, boltSmooth, 1e-6 * boltSmooth);
  const double boltVolume = validateMesh(bolt).signedVolume.value_or(0.0);
  EXPECT_NEAR(boltVolume, boltSmooth * polygon, 3e-3 * boltSmooth * polygon) << "smooth " << boltSmooth;
  // Nut: the hexagon prism (exact: its corners are vertices) minus the threaded hole.
  const double s = parts.acrossFlats;
  const double hexagon = std::sqrt(3.0) / 2 * s * s;
  const double hole = parts.nutTurns * std::numbers::pi * integralR2(parts.radialClearance) * polygon;
  const double nutExpected = parts.nutTurns * p * hexagon - hole;
  const double nutVolume = validateMesh(nut).signedVolume.value_or(0.0);
  EXPECT_NEAR(nutVolume, nutExpected, 3e-3 * hole) << "hole " << hole;
}

TEST(ThreadMeshes, BadParametersAreRefusedByName) {
  const IsoThread m16{};
  auto expectInvalid = [](auto make, const char* words) {
    try {
      make();
      ADD_FAILURE() << "no error for " << words;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  expectInvalid([&] { makeThreadedRod({0.016, -1.0}, 4, 24); }, "pitch");
  expectInvalid([&] { makeThreadedRod({0.016, 0.02}, 4, 24); }, "too coarse");
  expectInvalid([&] { makeThreadedRod({std::nan(""), 0.002}, 4, 24); }, "major diameter");
  expectInvalid([&] { makeThreadedRod(m16, 0, 24); }, "turns");
  expectInvalid([&] { makeThreadedRod(m16, 4, 5); }, "segments");
  expectInvalid([&] { makeHexNut(m16, -1e-4, 0.024, 4, 24); }, "clearance");
  expectInvalid([&] { makeHexNut(m16, 1e-4, 0.016, 4, 24); }, "across flats");
  expectInvalid([&] { makeHexNut(m16, 1e-4, 0.024, 4, 16); }, "multiple of 6");
}

}  // namespace
}  // namespace clod
