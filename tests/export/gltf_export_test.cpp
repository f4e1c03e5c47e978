// encodeGlb against independent readers: TinyGLTF's loader (a peer implementation) and the
// hand-written GLB reader of glb_reader.h, with expected values from the input meshes and poses
// (analytic box and sphere normals, the given keyframes).
#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include "clod/error.h"
#include "clod/gltf_export.h"
#include "clod/primitives.h"
#include "export/glb_reader.h"

namespace clod {
namespace {

using test::accessorValues;
using test::parseGlb;

// Float rounding of a coordinate of magnitude <= 2 is below 2.4e-7; 1e-6 leaves room.
constexpr double kFloatTol = 1e-6;

Pose makePose(const Vec3& t, double angle, const Vec3& axis) {
  Pose p;
  p.translation = t;
  p.rotation = Quat(Eigen::AngleAxisd(angle, axis.normalized()));
  return p;
}

struct Fixture {
  TriangleMesh box = makeBox(Vec3(1.0, 0.5, 0.25));
  TriangleMesh ball = makeIcosphere(0.5, 2);
  GltfScene scene;
  Fixture() {
    GltfBody ground{"ground", &box, true, makePose(Vec3(0, 0, -1), 0.0, Vec3::UnitZ()), {}};
    GltfBody crate{"crate", &box, false, makePose(Vec3(0, 0, 2), 0.3, Vec3(1, 1, 0)), {}};
    GltfBody sphere{"ball \"quoted\"", &ball, false, makePose(Vec3(1, 0, 3), 0.0, Vec3::UnitX()), {}};
    for (int k = 0; k < 7; ++k) {
      scene.keyTimes.push_back(k / 60.0);
      crate.keyframes.push_back(makePose(Vec3(0.1 * k, 0, 2 - 0.05 * k * k), 0.3 + 0.9 * k, Vec3(1, 1, 0)));
      Pose p = makePose(Vec3(1, 0.2 * k, 3), 0.4 * k, Vec3(0, 1, 0.5));
      // Alternate the quaternion's sign in the input: the file must still be sign-continuous.
      if (k % 2) p.rotation.coeffs() = -p.rotation.coeffs();
      sphere.keyframes.push_back(p);
    }
    crate.initialPose = crate.keyframes[0];
    sphere.initialPose = sphere.keyframes[0];
    scene.bodies = {ground, crate, sphere};
  }
};

tinygltf::Model loadWithTinyGltf(const std::string& bytes) {
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  const bool ok = loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                              static_cast<unsigned int>(bytes.size()));
  EXPECT_TRUE(ok) << err;
  EXPECT_TRUE(err.empty()) << err;
  EXPECT_TRUE(warn.empty()) << warn;
  return model;
}

TEST(GltfExport, TinyGltfLoadsTheFileWithOneNodePerBodyAndTheirNamesAndExtras) {
  Fixture f;
  const std::string bytes = encodeGlb(f.scene);
  const tinygltf::Model model = loadWithTinyGltf(bytes);
  EXPECT_EQ(model.asset.version, "2.0");
  ASSERT_EQ(model.nodes.size(), 3u);
  ASSERT_EQ(model.scenes.size(), 1u);
  EXPECT_EQ(model.scenes[0].nodes, (std::vector<int>{0, 1, 2}));
  for (std::size_t i = 0; i < 3; ++i) {
    const tinygltf::Node& node = model.nodes[i];
    EXPECT_EQ(node.name, f.scene.bodies[i].name);
    ASSERT_TRUE(node.extras.IsObject());
    EXPECT_EQ(node.extras.Get("body").GetNumberAsInt(), int(i));
    EXPECT_EQ(node.extras.Get("static").Get<bool>(), f.scene.bodies[i].isStatic);
    ASSERT_EQ(node.translation.size(), 3u);
    ASSERT_EQ(node.rotation.size(), 4u);
    const Pose& pose = f.scene.bodies[i].initialPose;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(node.translation[c], pose.translation[c], kFloatTol);
    const Quat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
    EXPECT_NEAR(std::abs(q.dot(pose.rotation)), 1.0, kFloatTol) << "same rotation up to sign";
    // Every primitive: triangles whose count matches the body's mesh.
    const tinygltf::Mesh& mesh = model.meshes.at(node.mesh);
    ASSERT_EQ(mesh.primitives.size(), 1u);
    EXPECT_EQ(model.accessors.at(mesh.primitives[0].indices).count, 3 * std::size_t(f.scene.bodies[i].mesh->triangleCount()));
  }
  ASSERT_EQ(model.animations.size(), 1u);
  EXPECT_EQ(model.animations[0].name, "simulation");
  EXPECT_EQ(model.animations[0].channels.size(), 4u) << "translation + rotation for each of the two moving bodies";
}

TEST(GltfExport, FramingBufferViewsAndPositionBoundsFollowTheSpecification) {
  Fixture f;
  const auto glb = parseGlb(encodeGlb(f.scene));  // throws on bad framing
  EXPECT_EQ(glb.json["asset"]["version"], "2.0");
  ASSERT_EQ(glb.json["buffers"].size(), 1u);
  EXPECT_LE(glb.json["buffers"][0]["byteLength"].get<std::size_t>(), glb.bin.size());
  for (const auto& view : glb.json["bufferViews"]) EXPECT_EQ(view.value("byteOffset", 0u) % 4, 0u);
  for (const auto& mesh : glb.json["meshes"]) {
    const int pos = mesh["primitives"][0]["attributes"]["POSITION"];
    const auto& acc = glb.json["accessors"][pos];
    ASSERT_TRUE(acc.contains("min") && acc.contains("max"));
    // The min/max must be the bounds of the stored values (the validator recomputes them).
    const std::vector<double> values = accessorValues(glb, pos);
    for (int c = 0; c < 3; ++c) {
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (std::size_t i = c; i < values.size(); i += 3) {
        lo = std::min(lo, values[i]);
        hi = std::max(hi, values[i]);
      }
      EXPECT_EQ(acc["min"][c].get<double>(), lo);
      EXPECT_EQ(acc["max"][c].get<double>(), hi);
    }
  }
}

// Triangle t of the primitive must be triangle t of the mesh, corner for corner.
void expectSameTriangles(const test::Glb& glb, int meshIndex, const TriangleMesh& mesh) {
  const auto& prim = glb.json["meshes"][meshIndex]["primitives"][0];
  const std::vector<double> pos = accessorValues(glb, prim["attributes"]["POSITION"]);
  const std::vector<double> idx = accessorValues(glb, prim["indices"]);
  ASSERT_EQ(idx.size(), 3 * std::size_t(mesh.triangleCount()));
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::size_t v = std::size_t(idx[3 * t + k]);
      ASSERT_LT(3 * v + 2, pos.size());
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(pos[3 * v + c], mesh.corner(t, k)[c], kFloatTol);
    }
}

TEST(GltfExport, BoxIsFlatShadedWithTwentyFourVerticesAndFaceNormals) {
  Fixture f;
  const auto glb = parseGlb(encodeGlb(f.scene));
  const int meshIndex = glb.json["nodes"][0]["mesh"];
  expectSameTriangles(glb, meshIndex, f.box);
  const auto& prim = glb.json["meshes"][meshIndex]["primitives"][0];
  const std::vector<double> pos = accessorValues(glb, prim["attributes"]["POSITION"]);
  const std::vector<double> nrm = accessorValues(glb, prim["attributes"]["NORMAL"]);
  const std::vector<double> idx = accessorValues(glb, prim["indices"]);
  // 8 corners x 3 faces meeting at 90 degrees (> the 40-degree crease) = 24 vertices.
  EXPECT_EQ(pos.size(), 24u * 3);
  ASSERT_EQ(nrm.size(), pos.size());
  for (std::size_t t = 0; t < idx.size() / 3; ++t) {
    // The face normal from the stored positions; each corner's normal must equal it.
    Vec3 p[3];
    for (int k = 0; k < 3; ++k) p[k] = Vec3(pos[3 * idx[3 * t + k]], pos[3 * idx[3 * t + k] + 1], pos[3 * idx[3 * t + k] + 2]);
    const Vec3 face = (p[1] - p[0]).cross(p[2] - p[0]).normalized();
    for (int k = 0; k < 3; ++k) {
      const std::size_t v = std::size_t(idx[3 * t + k]);
      EXPECT_NEAR((Vec3(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]) - face).norm(), 0.0, kFloatTol) << "triangle " << t;
    }
  }
}

TEST(GltfExport, SphereIsSmoothWithNormalsInsideTheConeOfItsFaceNormals) {
  Fixture f;
  const auto glb = parseGlb(encodeGlb(f.scene));
  const int meshIndex = glb.json["nodes"][2]["mesh"];
  expectSameTriangles(glb, meshIndex, f.ball);
  const auto& prim = glb.json["meshes"][meshIndex]["primitives"][0];
  const std::vector<double> pos = accessorValues(glb, prim["attributes"]["POSITION"]);
  const std::vector<double> nrm = accessorValues(glb, prim["attributes"]["NORMAL"]);
  // Neighbouring faces of an icosphere differ by far less than 40 degrees: no vertex is split.
  EXPECT_EQ(pos.size(), 3 * std::size_t(f.ball.vertexCount()));
  // A normalised positive combination of unit vectors lies inside any cone that holds them all;
  // the cone here: around the radial direction, with half-angle the largest angle between the
  // radial direction and a face normal at that vertex (computed from the input mesh).
  std::vector<double> cone(f.ball.vertexCount(), 0.0);
  for (std::uint32_t t = 0; t < f.ball.triangleCount(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = f.ball.triangles[t][k];
      const double angle = std::acos(std::clamp(f.ball.triangleNormal(t).dot(f.ball.vertices[v].normalized()), -1.0, 1.0));
      cone[v] = std::max(cone[v], angle);
    }
  for (std::size_t v = 0; v < pos.size() / 3; ++v) {
    const Vec3 p(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]), n(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]);
    EXPECT_NEAR(n.norm(), 1.0, kFloatTol);
    // Find the input vertex at this position to get its cone.
    std::uint32_t src = 0;
    for (std::uint32_t u = 1; u < f.ball.vertexCount(); ++u)
      if ((f.ball.vertices[u] - p).norm() < (f.ball.vertices[src] - p).norm()) src = u;
    const double angle = std::acos(std::clamp(n.normalized().dot(p.normalized()), -1.0, 1.0));
    EXPECT_LE(angle, cone[src] + 1e-5) << "vertex " << v;  // 1e-5 rad: float rounding of n and p
  }
}

TEST(GltfExport, AnimationKeyframesMatchTheGivenPosesWithSignContinuousUnitQuaternions) {
  Fixture f;
  const auto glb = parseGlb(encodeGlb(f.scene));
  const auto& anim = glb.json["animations"][0];
  EXPECT_EQ(anim["name"], "simulation");
  int checked = 0;
  for (const auto& channel : anim["channels"]) {
    const int node = channel["target"]["node"];
    const std::string path = channel["target"]["path"];
    const auto& sampler = anim["samplers"][channel["sampler"].get<int>()];
    EXPECT_EQ(sampler.value("interpolation", "LINEAR"), "LINEAR");
    const auto& input = glb.json["accessors"][sampler["input"].get<int>()];
    ASSERT_TRUE(input.contains("min") && input.contains("max")) << "sampler inputs need min/max";
    const std::vector<double> times = accessorValues(glb, sampler["input"]);
    ASSERT_EQ(times.size(), f.scene.keyTimes.size());
    for (std::size_t k = 0; k < times.size(); ++k) {
      EXPECT_NEAR(times[k], f.scene.keyTimes[k], 1e-7);
      if (k) {
        EXPECT_GT(times[k], times[k - 1]);
      }
    }
    const GltfBody& body = f.scene.bodies.at(node);
    ASSERT_FALSE(body.isStatic) << "static bodies get no channels";
    const std::vector<double> out = accessorValues(glb, sampler["output"]);
    if (path == "translation") {
      ASSERT_EQ(out.size(), 3 * times.size());
      for (std::size_t k = 0; k < times.size(); ++k)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[3 * k + c], body.keyframes[k].translation[c], kFloatTol);
    } else {
      ASSERT_EQ(path, "rotation");
      ASSERT_EQ(out.size(), 4 * times.size());
      for (std::size_t k = 0; k < times.size(); ++k) {
        const Quat q(out[4 * k + 3], out[4 * k], out[4 * k + 1], out[4 * k + 2]);  // file order x y z w
        EXPECT_NEAR(q.norm(), 1.0, kFloatTol);
        EXPECT_NEAR(std::abs(q.dot(body.keyframes[k].rotation)), 1.0, kFloatTol);
        if (k) {
          const Quat prev(out[4 * k - 1], out[4 * k - 4], out[4 * k - 3], out[4 * k - 2]);
          EXPECT_GE(q.dot(prev), 0.0) << "key " << k << " flips sign";
        }
      }
    }
    ++checked;
  }
  EXPECT_EQ(checked, 4);
}

TEST(GltfExport, NoKeyTimesMeansNoAnimationAndEqualScenesGiveEqualBytes) {
  Fixture f;
  f.scene.keyTimes.clear();
  const std::string a = encodeGlb(f.scene), b = encodeGlb(f.scene);
  EXPECT_EQ(a, b);
  const auto glb = parseGlb(a);
  EXPECT_FALSE(glb.json.contains("animations"));
}

void expectInvalid(const GltfScene& scene, const std::string& fragment) {
  try {
    encodeGlb(scene);
    ADD_FAILURE() << "no error; expected one mentioning " << fragment;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(GltfExport, BadScenesThrowInvalidArgumentNamingTheCulprit) {
  expectInvalid(GltfScene{}, "no bodies");
  {
    Fixture f;
    f.scene.bodies[1].mesh = nullptr;
    expectInvalid(f.scene, "crate");
  }
  {
    Fixture f;
    f.scene.keyTimes[3] = f.scene.keyTimes[2];
    expectInvalid(f.scene, "keyTimes[3]");
  }
  {
    Fixture f;
    f.scene.bodies[2].keyframes.pop_back();
    expectInvalid(f.scene, "6 keyframes for 7 key times");
  }
  {
    Fixture f;
    f.scene.bodies[1].keyframes[4].translation.x() = std::numeric_limits<double>::quiet_NaN();
    expectInvalid(f.scene, "keyframe 4");
  }
  {
    Fixture f;
    TriangleMesh broken = f.box;
    broken.triangles[5][1] = 99;
    f.scene.bodies[0].mesh = &broken;
    expectInvalid(f.scene, "vertex index 99");
  }
}

}  // namespace
}  // namespace clod
