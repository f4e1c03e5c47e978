#include "clod/mass_properties.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "clod/error.h"
#include "clod/mesh_validation.h"
#include "clod/primitives.h"
#include "mesh_test_support.h"

namespace clod {
namespace {

constexpr double kPi = std::numbers::pi;

// Analytic inertia of a solid box of full side lengths (2a, 2b, 2c) about its centre.
Mat3 boxInertia(const Vec3& half, double mass) {
  const Vec3 s2 = (2.0 * half).cwiseAbs2();
  return (mass / 12.0 * Vec3(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y())).asDiagonal();
}

ErrorCode thrownCode(const TriangleMesh& mesh) {
  try {
    computeMassProperties(mesh);
  } catch (const Error& e) {
    return e.code();
  }
  ADD_FAILURE() << "computeMassProperties did not throw";
  return ErrorCode::kInvalidArgument;
}

// For boxes the integrals are sums of a few dozen products of the coordinates, so the only error
// is rounding: 1e-13 relative to the answer's scale leaves two orders of magnitude of margin over
// ~100 ulps of accumulated rounding.
constexpr double kRoundingRel = 1e-13;

TEST(MassProperties, UnitCubeMatchesAnalyticValues) {
  const MassProperties mp = computeMassProperties(makeBox(Vec3(0.5, 0.5, 0.5)));
  EXPECT_NEAR(mp.volume, 1.0, kRoundingRel);
  EXPECT_NEAR(mp.mass, 1.0, kRoundingRel);
  EXPECT_LE(mp.centerOfMass.norm(), kRoundingRel);
  // I = m (1 + 1) / 12 = 1/6 on each axis, no products of inertia.
  EXPECT_LE((mp.inertia - Mat3::Identity() / 6.0).norm(), kRoundingRel);
}

TEST(MassProperties, RotatedTranslatedBoxMatchesAnalyticValues) {
  const Vec3 half(0.3, 1.1, 2.0);
  const double density = 2.5;
  const Quat rotation = Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  const Vec3 translation(10.0, -4.0, 7.5);
  TriangleMesh box = makeBox(half);
  for (Vec3& v : box.vertices) v = rotation * v + translation;

  const MassProperties mp = computeMassProperties(box, density);
  const double volume = 8.0 * half.prod();
  const double mass = density * volume;
  const Mat3 expected = rotation.toRotationMatrix() * boxInertia(half, mass) * rotation.toRotationMatrix().transpose();
  const double scale = expected.norm();
  EXPECT_NEAR(mp.volume, volume, kRoundingRel * volume);
  EXPECT_NEAR(mp.mass, mass, kRoundingRel * mass);
  EXPECT_LE((mp.centerOfMass - translation).norm(), kRoundingRel * translation.norm());
  EXPECT_LE((mp.inertia - expected).norm(), kRoundingRel * scale);
}

TEST(MassProperties, TwoSeparateBoxesFollowTheParallelAxisTheorem) {
  // Non-convex as a whole: checks the integrals are not relying on convexity.
  const Vec3 halfA(1, 1, 1), halfB(0.5, 2, 1);
  const Vec3 centreA(-3, 0, 0), centreB(4, 1, -2);
  TriangleMesh mesh = makeBox(halfA);
  for (Vec3& v : mesh.vertices) v += centreA;
  const TriangleMesh b = makeBox(halfB);
  const std::uint32_t base = mesh.vertexCount();
  for (const Vec3& v : b.vertices) mesh.vertices.push_back(v + centreB);
  for (const Triangle& t : b.triangles) mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});

  const double massA = 8 * halfA.prod(), massB = 8 * halfB.prod();
  const Vec3 com = (massA * centreA + massB * centreB) / (massA + massB);
  auto shifted = [&](const Vec3& half, double m, const Vec3& centre) {
    const Vec3 d = centre - com;
    return Mat3(boxInertia(half, m) + m * (d.squaredNorm() * Mat3::Identity() - d * d.transpose()));
  };
  const Mat3 expected = shifted(halfA, massA, centreA) + shifted(halfB, massB, centreB);
  const MassProperties mp = computeMassProperties(mesh);
  EXPECT_NEAR(mp.volume, massA + massB, kRoundingRel * 24);
  EXPECT_LE((mp.centerOfMass - com).norm(), kRoundingRel * 10);
  EXPECT_LE((mp.inertia - expected).norm(), kRoundingRel * expected.norm());
}

TEST(MassProperties, IcosphereIsBracketedByItsInscribedAndCircumscribedBalls) {
  // The icosphere is a convex polyhedron with every vertex on the sphere of radius r, so it lies
  // inside that ball and contains the ball of radius rIn = the smallest distance from the centre
  // to a face plane. Volume and each diagonal inertia term (integrals of non-negative functions)
  // are therefore bracketed by the ball values: 4/3 pi rho^3 and 8/15 pi rho^5. The bracket width
  // is the tessellation error, ~(1 - rIn/r) * 5 relative, here < 0.5 %.
  const double r = 1.5;
  const std::uint32_t subdivisions = test::sanitizerRun() ? 4 : 5;
  const TriangleMesh sphere = makeIcosphere(r, subdivisions);
  double rIn = r;
  for (std::uint32_t t = 0; t < sphere.triangleCount(); ++t)
    rIn = std::min(rIn, sphere.triangleNormal(t).dot(sphere.corner(t, 0)));
  ASSERT_GT(rIn, 0.99 * r);

  const MassProperties mp = computeMassProperties(sphere);
  const double slack = 1e-12;  // rounding, relative
  EXPECT_GE(mp.volume, 4.0 / 3.0 * kPi * std::pow(rIn, 3) * (1 - slack));
  EXPECT_LE(mp.volume, 4.0 / 3.0 * kPi * std::pow(r, 3) * (1 + slack));
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_GE(mp.inertia(axis, axis), 8.0 / 15.0 * kPi * std::pow(rIn, 5) * (1 - slack));
    EXPECT_LE(mp.inertia(axis, axis), 8.0 / 15.0 * kPi * std::pow(r, 5) * (1 + slack));
  }
  // The icosahedral symmetry group fixes only multiples of the identity among symmetric tensors,
  // and it contains the central inversion: the tensor is isotropic and the centre is the origin.
  const double scale = mp.inertia(0, 0);
  EXPECT_LE((mp.inertia - scale * Mat3::Identity()).norm(), 1e-12 * scale);
  EXPECT_LE(mp.centerOfMass.norm(), 1e-12 * r);
}

TEST(MassProperties, CylinderMatchesTheRegularPrismFormulas) {
  // A regular n-gon prism (circumradius r, apothem d = r cos(pi/n), height H = 2h):
  //   area A = n/2 r^2 sin(2 pi/n); polar moment of the n-gon
  //   J = n * integral over one wedge of rho^2 = n d^4 / 2 (t + t^3/3), t = tan(pi/n)
  //   (integrate rho^3 from 0 to d / cos(theta), theta in [-pi/n, pi/n]);
  //   Izz = H J; Ixx = Iyy = H J/2 + A H^3/12 (a regular polygon's second moment is isotropic).
  const double r = 0.8, h = 1.25;
  for (std::uint32_t n : {3u, 5u, 8u, 33u}) {
    const MassProperties mp = computeMassProperties(makeCylinder(r, h, n));
    const double H = 2 * h;
    const double area = n / 2.0 * r * r * std::sin(2 * kPi / n);
    const double d = r * std::cos(kPi / n), t = std::tan(kPi / n);
    const double polar = n * std::pow(d, 4) / 2.0 * (t + t * t * t / 3.0);
    const double izz = H * polar, ixx = H * polar / 2.0 + area * H * H * H / 12.0;
    EXPECT_NEAR(mp.volume, area * H, kRoundingRel * area * H) << n;
    EXPECT_LE(mp.centerOfMass.norm(), kRoundingRel * r) << n;
    EXPECT_NEAR(mp.inertia(2, 2), izz, kRoundingRel * izz) << n;
    EXPECT_NEAR(mp.inertia(0, 0), ixx, kRoundingRel * ixx) << n;
    EXPECT_NEAR(mp.inertia(1, 1), ixx, kRoundingRel * ixx) << n;
    EXPECT_NEAR(mp.inertia(0, 1), 0.0, kRoundingRel * ixx) << n;
    EXPECT_NEAR(mp.inertia(0, 2), 0.0, kRoundingRel * ixx) << n;
  }
}

TEST(MassProperties, InsideOutMeshGivesTheSameSolid) {
  TriangleMesh box = makeBox(Vec3(1, 2, 3));
  const MassProperties outward = computeMassProperties(box);
  flipOrientation(box);
  const MassProperties inward = computeMassProperties(box);
  EXPECT_NEAR(inward.volume, 48.0, kRoundingRel * 48.0);
  EXPECT_NEAR(outward.volume, 48.0, kRoundingRel * 48.0);
  EXPECT_LE((inward.inertia - boxInertia(Vec3(1, 2, 3), 48.0)).norm(), kRoundingRel * 1e3);
}

TEST(MassProperties, OpenMeshThrowsUnsupportedMesh) {
  TriangleMesh box = makeBox(Vec3(1, 1, 1));
  box.triangles.pop_back();
  EXPECT_EQ(thrownCode(box), ErrorCode::kUnsupportedMesh);
}

TEST(MassProperties, OpenMeshFallsBackToTheSolidBoxOfItsBounds) {
  // A 2 x 4 x 6 box with one triangle missing is open; the fallback is the analytic solid box of
  // the same bounds at density 2 (mass 96), centred at the translation.
  TriangleMesh box = makeBox(Vec3(1, 2, 3));
  box.triangles.pop_back();
  for (Vec3& v : box.vertices) v += Vec3(5, -1, 2);
  const MassProperties mp = computeMassPropertiesOrBoundingBox(box, 2.0);
  EXPECT_NEAR(mp.volume, 48.0, kRoundingRel * 48.0);
  EXPECT_NEAR(mp.mass, 96.0, kRoundingRel * 96.0);
  EXPECT_LE((mp.centerOfMass - Vec3(5, -1, 2)).norm(), kRoundingRel * 10.0);
  EXPECT_LE((mp.inertia - boxInertia(Vec3(1, 2, 3), 96.0)).norm(), kRoundingRel * 1e3);
  // A closed mesh keeps its exact properties, and other errors still propagate.
  const MassProperties closed = computeMassPropertiesOrBoundingBox(makeBox(Vec3(1, 2, 3)));
  EXPECT_NEAR(closed.volume, 48.0, kRoundingRel * 48.0);
  EXPECT_THROW(computeMassPropertiesOrBoundingBox(TriangleMesh{}), Error);
}

TEST(MassProperties, InconsistentOrientationThrowsUnsupportedMesh) {
  TriangleMesh box = makeBox(Vec3(1, 1, 1));
  std::swap(box.triangles[0][1], box.triangles[0][2]);
  EXPECT_EQ(thrownCode(box), ErrorCode::kUnsupportedMesh);
}

TEST(MassProperties, FlatClosedMeshThrowsUnsupportedMesh) {
  TriangleMesh sheet;
  sheet.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  sheet.triangles = {{0, 1, 2}, {0, 2, 1}};
  EXPECT_EQ(thrownCode(sheet), ErrorCode::kUnsupportedMesh);
}

TEST(MassProperties, FatalMeshProblemsKeepTheirOwnCodes) {
  TriangleMesh box = makeBox(Vec3(1, 1, 1));
  box.vertices[3].x() = std::nan("");
  EXPECT_EQ(thrownCode(box), ErrorCode::kNonFiniteVertex);
  EXPECT_EQ(thrownCode(TriangleMesh{}), ErrorCode::kNoTriangles);
  try {
    computeMassProperties(makeBox(Vec3(1, 1, 1)), -1.0);
    ADD_FAILURE() << "negative density accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
  }
}

}  // namespace
}  // namespace clod
