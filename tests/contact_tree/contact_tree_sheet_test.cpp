// The contact tree of a sheet (an open mesh that encloses nothing: a floor quad, a terrain):
// signed by its pseudonormals, behind it is inside (docs/contact-tree.md, "Sheets").
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "clod/contact_tree.h"
#include "clod/contact_tree_builder.h"
#include "clod/proximity.h"
#include "support/floor_quad.h"
#include "support/test_scale.h"

namespace clod {
namespace {

// A 13.7 x 3 m floor quad in two long triangles (a slope's ground in a user's scene), top at
// z = 0.25. Oracle: the plane's signed distance z - 0.25 over the footprint. Signed by the winding number, which never
// reaches 1/2 off a sheet, the field had no inside and a box slid through; with the sign
// inference across the plane beyond the border, points 0.67 above the floor read -0.67.
TEST(ContactTreeSheet, FloorQuadIsSignedByItsSideOverItsFootprint) {
  const double hx = 6.86, hy = 1.5, z = 0.25;
  const TriangleMesh quad = test::makeFloorQuad(hx, hy, z);
  ContactTreeSettings settings;
  if (test::sanitizerRun()) settings.errorRel = 4e-3;  // the checks hold against the tree's own bound
  const ContactTree tree = buildContactTree(MeshDistance(quad), settings);
  // Stored corners are floats: 2^-23 of the diagonal covers their rounding (contact_tree_box_test).
  const double rounding = std::ldexp(Vec3(2 * hx, 2 * hy, 0).norm(), -23);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (int i = 0; i < 5000; ++i) {
    // Over the footprint: the nearest point of the quad is the point's foot on the plane.
    const Vec3 p(0.95 * hx * uni(rng), 0.95 * hy * uni(rng), z + 0.7 * uni(rng));
    const ContactFieldSample s = tree.sample(p);
    ASSERT_NEAR(s.distance, p.z() - z, s.errorBound + rounding) << p.transpose();
  }
}

}  // namespace
}  // namespace clod
