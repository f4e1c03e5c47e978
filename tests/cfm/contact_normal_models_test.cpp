// Contact normal models against analytic answers on a box whose sphere-tree is written by hand:
// D&O is the centre-to-point direction; averaging a corner's two faces gives the diagonal (the
// paper's argument against it, section 6); the closest feature map gives the face normal.
#include <cmath>

#include <gtest/gtest.h>

#include "clod/closest_feature_map.h"
#include "clod/contact_normal.h"
#include "clod/error.h"
#include "clod/primitives.h"
#include "clod/proximity.h"

namespace clod {
namespace {

double angle(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// The box's triangles whose face normal is `axisNormal`, found from the geometry.
std::vector<std::uint32_t> faceTriangles(const TriangleMesh& mesh, const Vec3& axisNormal) {
  std::vector<std::uint32_t> result;
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    const Vec3& a = mesh.vertices[tri[0]];
    const Vec3 n = (mesh.vertices[tri[1]] - a).cross(mesh.vertices[tri[2]] - a).normalized();
    if (n.dot(axisNormal) > 0.999) result.push_back(t);
  }
  return result;
}

// A one-level tree: the sphere around the unit cube [-1,1]^3, responsible only for the +x and +y
// faces (the region of the cube's +x/+y edge, as a deeper sphere of a real tree would be).
struct CornerCase {
  TriangleMesh mesh = makeBox(Vec3(1.0, 1.0, 1.0));
  SphereTree tree;
  ClosestFeatureMap maps;
  CornerCase() {
    tree.centerX = {0.0};
    tree.centerY = {0.0};
    tree.centerZ = {0.0};
    tree.radius = {std::sqrt(3.0)};
    tree.parent = {kNoSphere};
    tree.firstChild = {0};
    tree.childCount = {0};
    tree.levelOffsets = {0, 1};
    tree.triangleList = faceTriangles(mesh, Vec3::UnitX());
    const std::vector<std::uint32_t> y = faceTriangles(mesh, Vec3::UnitY());
    tree.triangleList.insert(tree.triangleList.end(), y.begin(), y.end());
    tree.triangleOffsets = {0, static_cast<std::uint32_t>(tree.triangleList.size())};
    ClosestFeatureMapSettings settings;
    settings.rootStacks = 16;
    maps = buildClosestFeatureMap(MeshDistance(mesh), tree, settings);
  }
};

TEST(ContactNormal, DinglianaIsTheCentreToPointDirection) {
  const CornerCase c;
  const Vec3 p(0.3, -1.2, 0.4);
  EXPECT_LE(angle(contactNormal(ContactNormalModel::kDingliana, c.tree, c.maps, 0, p), p.normalized()), 1e-12);
}

TEST(ContactNormal, AveragingTwoPerpendicularFacesGivesTheDiagonal) {
  const CornerCase c;
  ASSERT_EQ(c.tree.triangles(0).size(), 4u) << "two triangles per box face";
  const Vec3 diagonal = Vec3(1.0, 1.0, 0.0).normalized();
  // The average ignores where the contact is: the diagonal for every point (float storage: 1e-6).
  for (const Vec3& p : {Vec3(1.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0), Vec3(1.0, 1.0, 0.5)}) {
    EXPECT_LE(angle(contactNormal(ContactNormalModel::kAverage, c.tree, c.maps, 0, p), diagonal), 1e-6);
  }
}

TEST(ContactNormal, ClosestFeatureMapGivesTheFaceNormalWhereTheAverageGivesTheDiagonal) {
  const CornerCase c;
  const double bound = normalCodecErrorBound(c.maps.settings().codec) + 1e-9;
  // Contacts at the face centres: the map knows which face is there.
  EXPECT_LE(angle(contactNormal(ContactNormalModel::kClosestFeatureMap, c.tree, c.maps, 0, Vec3(1.0, 0.0, 0.0)), Vec3::UnitX()), bound);
  EXPECT_LE(angle(contactNormal(ContactNormalModel::kClosestFeatureMap, c.tree, c.maps, 0, Vec3(0.0, 1.0, 0.0)), Vec3::UnitY()), bound);
  // Exactly over the edge the nearest feature is the edge, whose pseudonormal is the diagonal.
  EXPECT_LE(angle(contactNormal(ContactNormalModel::kClosestFeatureMap, c.tree, c.maps, 0, Vec3(1.0, 1.0, 0.0)),
                  Vec3(1.0, 1.0, 0.0).normalized()),
            bound);
}

TEST(ContactNormal, AverageOfAClosedMeshFallsBackToDingliana) {
  // The root of a closed box bounds all six faces: the area-weighted normals cancel.
  CornerCase c;
  c.tree.triangleList.clear();
  for (std::uint32_t t = 0; t < c.mesh.triangleCount(); ++t) c.tree.triangleList.push_back(t);
  c.tree.triangleOffsets = {0, c.mesh.triangleCount()};
  const ClosestFeatureMap maps = buildClosestFeatureMap(MeshDistance(c.mesh), c.tree, {});
  EXPECT_EQ(maps.averageNormal(0), Vec3::Zero());
  const Vec3 p(0.2, 0.9, -0.4);
  EXPECT_LE(angle(contactNormal(ContactNormalModel::kAverage, c.tree, maps, 0, p), p.normalized()), 1e-12);
  // D&O at the centre itself has no direction: it uses the average, then +z.
  EXPECT_EQ(contactNormal(ContactNormalModel::kDingliana, c.tree, maps, 0, Vec3::Zero()), Vec3::UnitZ());
}

TEST(ContactNormalModelNames, RoundTripAndRejectUnknownNames) {
  for (ContactNormalModel model : allContactNormalModels()) {
    EXPECT_EQ(parseContactNormalModel(contactNormalModelName(model)), model);
  }
  EXPECT_EQ(contactNormalModelName(ContactNormalModel::kDingliana), "dos");
  try {
    parseContactNormalModel("DOS");
    ADD_FAILURE() << "accepted 'DOS'";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("'DOS'"), std::string::npos);
  }
}

}  // namespace
}  // namespace clod
