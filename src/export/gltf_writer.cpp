#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <sstream>
#include <unordered_map>

#include <tiny_gltf.h>

#include "clod/atomic_file.h"
#include "clod/error.h"
#include "clod/gltf_export.h"

namespace clod {
namespace {

// glTF 2.0 enumerations (specification section 5: accessor.componentType, bufferView.target,
// mesh.primitive.mode).
constexpr int kComponentFloat = 5126;
constexpr int kComponentUint32 = 5125;
constexpr int kTargetArrayBuffer = 34962;
constexpr int kTargetElementArrayBuffer = 34963;
constexpr int kModeTriangles = 4;

// A mesh with per-vertex normals split at creases, ready for the buffer.
struct ShadedMesh {
  std::vector<float> positions;  // x y z per vertex
  std::vector<float> normals;
  std::vector<std::uint32_t> indices;  // 3 per triangle, mesh order
};

std::string bodyLabel(std::size_t i, const GltfBody& b) {
  return "body " + std::to_string(i) + (b.name.empty() ? std::string() : " ('" + b.name + "')");
}

// Angle-weighted vertex normals (Thürmer & Wüthrich 1998) restricted, per triangle corner, to the
// incident triangles whose face normal lies within the crease angle of this triangle's: a box
// corner gets three flat normals, a smooth surface one shared normal. Corners of one vertex with
// the same resulting normal share an output vertex, so smooth meshes are not unwelded.
ShadedMesh shadeMesh(const TriangleMesh& mesh) {
  const std::uint32_t nv = mesh.vertexCount(), nt = mesh.triangleCount();
  std::vector<Vec3> faceNormal(nt);
  std::vector<std::array<double, 3>> cornerAngle(nt);
  for (std::uint32_t t = 0; t < nt; ++t) {
    faceNormal[t] = mesh.triangleNormal(t);
    for (int k = 0; k < 3; ++k) {
      const Vec3 e1 = mesh.corner(t, (k + 1) % 3) - mesh.corner(t, k);
      const Vec3 e2 = mesh.corner(t, (k + 2) % 3) - mesh.corner(t, k);
      const double denom = e1.norm() * e2.norm();
      cornerAngle[t][k] = denom > 0.0 ? std::acos(std::clamp(e1.dot(e2) / denom, -1.0, 1.0)) : 0.0;
    }
  }
  // Incident (triangle, corner) lists per vertex, CSR.
  std::vector<std::uint32_t> offsets(nv + 1, 0), incident(3 * std::size_t(nt));
  for (const Triangle& tri : mesh.triangles)
    for (std::uint32_t v : tri) ++offsets[v + 1];
  for (std::uint32_t v = 0; v < nv; ++v) offsets[v + 1] += offsets[v];
  {
    std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (std::uint32_t t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k) incident[fill[mesh.triangles[t][k]]++] = 3 * t + std::uint32_t(k);
  }
  const double cosCrease = std::cos(kGltfCreaseAngle);
  ShadedMesh out;
  out.indices.resize(3 * std::size_t(nt));
  std::vector<std::pair<Vec3f, std::uint32_t>> made;  // output vertices of the current vertex
  for (std::uint32_t v = 0; v < nv; ++v) {
    made.clear();
    for (std::uint32_t i = offsets[v]; i < offsets[v + 1]; ++i) {
      const std::uint32_t t = incident[i] / 3;
      Vec3 sum = Vec3::Zero(), all = Vec3::Zero();
      for (std::uint32_t j = offsets[v]; j < offsets[v + 1]; ++j) {
        const std::uint32_t u = incident[j] / 3, k = incident[j] % 3;
        const Vec3 w = cornerAngle[u][k] * faceNormal[u];
        all += w;
        if (faceNormal[u].dot(faceNormal[t]) >= cosCrease) sum += w;
      }
      // Degenerate neighbourhoods (zero-area triangles) fall back to all neighbours, then +Z, so
      // every NORMAL is unit length as the specification requires.
      Vec3 n = sum.norm() > 1e-300 ? sum.normalized() : (all.norm() > 1e-300 ? all.normalized() : Vec3::UnitZ());
      const Vec3f nf = n.cast<float>().normalized();
      std::uint32_t index = 0;
      bool found = false;
      for (const auto& [existing, id] : made) {
        if ((existing - nf).squaredNorm() < 1e-12f) {
          index = id;
          found = true;
          break;
        }
      }
      if (!found) {
        index = static_cast<std::uint32_t>(out.positions.size() / 3);
        const Vec3& p = mesh.vertices[v];
        out.positions.insert(out.positions.end(), {float(p.x()), float(p.y()), float(p.z())});
        out.normals.insert(out.normals.end(), {nf.x(), nf.y(), nf.z()});
        made.emplace_back(nf, index);
      }
      out.indices[incident[i]] = index;
    }
  }
  return out;
}

// Appends raw bytes to the single buffer at a 4-byte boundary (glTF requires accessor offsets
// aligned to the component size; 4 covers float and uint32) and adds a buffer view over them.
int addBufferView(tinygltf::Model& model, const void* data, std::size_t bytes, int target) {
  std::vector<unsigned char>& buffer = model.buffers[0].data;
  buffer.resize((buffer.size() + 3) / 4 * 4, 0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buffer.size();
  view.byteLength = bytes;
  view.target = target;
  const auto* p = static_cast<const unsigned char*>(data);
  buffer.insert(buffer.end(), p, p + bytes);
  model.bufferViews.push_back(std::move(view));
  return static_cast<int>(model.bufferViews.size() - 1);
}

int addAccessor(tinygltf::Model& model, int view, int componentType, int type, std::size_t count,
                std::vector<double> min = {}, std::vector<double> max = {}) {
  tinygltf::Accessor a;
  a.bufferView = view;
  a.byteOffset = 0;
  a.componentType = componentType;
  a.type = type;
  a.count = count;
  a.minValues = std::move(min);
  a.maxValues = std::move(max);
  model.accessors.push_back(std::move(a));
  return static_cast<int>(model.accessors.size() - 1);
}

// Float accessor with per-component min/max of the float values actually stored.
int addFloatAccessor(tinygltf::Model& model, const std::vector<float>& values, int components, int type,
                     int target, bool withBounds) {
  const int view = addBufferView(model, values.data(), values.size() * sizeof(float), target);
  std::vector<double> lo, hi;
  if (withBounds) {
    lo.assign(components, std::numeric_limits<double>::infinity());
    hi.assign(components, -std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < values.size(); ++i) {
      const int c = int(i % std::size_t(components));
      lo[c] = std::min(lo[c], double(values[i]));
      hi[c] = std::max(hi[c], double(values[i]));
    }
  }
  return addAccessor(model, view, kComponentFloat, type, values.size() / std::size_t(components), lo, hi);
}

bool finitePose(const Pose& p) { return p.translation.allFinite() && p.rotation.coeffs().allFinite() && p.rotation.norm() > 0.0; }

void checkScene(const GltfScene& scene) {
  if (scene.bodies.empty()) throw Error(ErrorCode::kInvalidArgument, "glTF export: the scene has no bodies");
  for (std::size_t i = 0; i < scene.keyTimes.size(); ++i) {
    if (!std::isfinite(scene.keyTimes[i]))
      throw Error(ErrorCode::kInvalidArgument, "glTF export: keyTimes[" + std::to_string(i) + "] is not finite");
    // Strictly increasing after the conversion to float, since that is what the file holds.
    if (i > 0 && !(float(scene.keyTimes[i]) > float(scene.keyTimes[i - 1])))
      throw Error(ErrorCode::kInvalidArgument,
                  "glTF export: keyTimes[" + std::to_string(i) + "] is not greater than keyTimes[" + std::to_string(i - 1) + "]");
  }
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const GltfBody& b = scene.bodies[i];
    if (!b.mesh) throw Error(ErrorCode::kInvalidArgument, "glTF export: " + bodyLabel(i, b) + " has no mesh");
    if (b.mesh->triangleCount() == 0)
      throw Error(ErrorCode::kInvalidArgument, "glTF export: " + bodyLabel(i, b) + ": mesh has no triangles");
    for (std::uint32_t v = 0; v < b.mesh->vertexCount(); ++v)
      if (!b.mesh->vertices[v].allFinite())
        throw Error(ErrorCode::kInvalidArgument, "glTF export: " + bodyLabel(i, b) + ": vertex " + std::to_string(v) + " is not finite");
    for (std::uint32_t t = 0; t < b.mesh->triangleCount(); ++t)
      for (std::uint32_t idx : b.mesh->triangles[t])
        if (idx >= b.mesh->vertexCount())
          throw Error(ErrorCode::kInvalidArgument, "glTF export: " + bodyLabel(i, b) + ": triangle " + std::to_string(t) +
                                                       ": vertex index " + std::to_string(idx) + " >= vertex count " +
                                                       std::to_string(b.mesh->vertexCount()));
    if (!finitePose(b.initialPose))
      throw Error(ErrorCode::kInvalidArgument, "glTF export: " + bodyLabel(i, b) + ": initial pose is not finite");
    if (b.isStatic || scene.keyTimes.empty()) continue;
    if (b.keyframes.size() != scene.keyTimes.size())
      throw Error(ErrorCode::kInvalidArgument, "glTF export: " + bodyLabel(i, b) + " has " + std::to_string(b.keyframes.size()) +
                                                   " keyframes for " + std::to_string(scene.keyTimes.size()) + " key times");
    for (std::size_t k = 0; k < b.keyframes.size(); ++k)
      if (!finitePose(b.keyframes[k]))
        throw Error(ErrorCode::kInvalidArgument, "glTF export: " + bodyLabel(i, b) + ": keyframe " + std::to_string(k) + " is not finite");
  }
}

// Unit quaternion as float x y z w, normalised after rounding to float.
std::array<float, 4> floatQuat(const Quat& q) {
  const Quat n = q.normalized();
  Eigen::Vector4f v(float(n.x()), float(n.y()), float(n.z()), float(n.w()));
  v.normalize();
  return {v[0], v[1], v[2], v[3]};
}

}  // namespace

std::string encodeGlb(const GltfScene& scene) {
  checkScene(scene);
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "clod";
  model.buffers.emplace_back();

  // Two plain PBR materials so static and moving bodies read apart in any viewer; each is added
  // only when a body uses it (validators flag unused objects).
  std::array<int, 2> materialIndex{-1, -1};
  auto material = [&](bool isStatic) {
    int& index = materialIndex[isStatic ? 0 : 1];
    if (index < 0) {
      tinygltf::Material m;
      m.name = isStatic ? "static" : "dynamic";
      m.pbrMetallicRoughness.baseColorFactor =
          isStatic ? std::vector<double>{0.55, 0.57, 0.6, 1.0} : std::vector<double>{0.85, 0.55, 0.3, 1.0};
      m.pbrMetallicRoughness.metallicFactor = 0.0;
      m.pbrMetallicRoughness.roughnessFactor = 0.8;
      index = static_cast<int>(model.materials.size());
      model.materials.push_back(std::move(m));
    }
    return index;
  };

  // One glTF mesh per (TriangleMesh object, material).
  std::map<std::pair<const TriangleMesh*, int>, int> meshIndex;
  std::unordered_map<const TriangleMesh*, std::array<int, 3>> meshAccessors;  // position, normal, indices
  tinygltf::Scene gltfScene;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const GltfBody& b = scene.bodies[i];
    const int materialId = material(b.isStatic);
    auto [it, inserted] = meshIndex.try_emplace({b.mesh, materialId}, int(model.meshes.size()));
    if (inserted) {
      auto acc = meshAccessors.find(b.mesh);
      if (acc == meshAccessors.end()) {
        const ShadedMesh shaded = shadeMesh(*b.mesh);
        const int pos = addFloatAccessor(model, shaded.positions, 3, TINYGLTF_TYPE_VEC3, kTargetArrayBuffer, true);
        const int nrm = addFloatAccessor(model, shaded.normals, 3, TINYGLTF_TYPE_VEC3, kTargetArrayBuffer, false);
        const int view = addBufferView(model, shaded.indices.data(), shaded.indices.size() * sizeof(std::uint32_t),
                                       kTargetElementArrayBuffer);
        const int idx = addAccessor(model, view, kComponentUint32, TINYGLTF_TYPE_SCALAR, shaded.indices.size());
        acc = meshAccessors.emplace(b.mesh, std::array<int, 3>{pos, nrm, idx}).first;
      }
      tinygltf::Primitive prim;
      prim.attributes["POSITION"] = acc->second[0];
      prim.attributes["NORMAL"] = acc->second[1];
      prim.indices = acc->second[2];
      prim.material = materialId;
      prim.mode = kModeTriangles;
      tinygltf::Mesh mesh;
      mesh.name = b.name;
      mesh.primitives.push_back(std::move(prim));
      model.meshes.push_back(std::move(mesh));
    }
    tinygltf::Node node;
    node.name = b.name;
    node.mesh = it->second;
    const Vec3& t = b.initialPose.translation;
    node.translation = {t.x(), t.y(), t.z()};
    const std::array<float, 4> q = floatQuat(b.initialPose.rotation);
    node.rotation = {q[0], q[1], q[2], q[3]};
    tinygltf::Value::Object extras;
    extras["body"] = tinygltf::Value(int(i));
    extras["static"] = tinygltf::Value(b.isStatic);
    node.extras = tinygltf::Value(std::move(extras));
    model.nodes.push_back(std::move(node));
    gltfScene.nodes.push_back(int(i));
  }
  model.scenes.push_back(std::move(gltfScene));
  model.defaultScene = 0;

  if (!scene.keyTimes.empty()) {
    std::vector<float> times(scene.keyTimes.begin(), scene.keyTimes.end());
    // Animation sampler inputs must carry min and max (specification 3.11).
    const int input = addFloatAccessor(model, times, 1, TINYGLTF_TYPE_SCALAR, 0, true);
    tinygltf::Animation anim;
    anim.name = "simulation";
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const GltfBody& b = scene.bodies[i];
      if (b.isStatic) continue;
      std::vector<float> translation, rotation;
      translation.reserve(3 * b.keyframes.size());
      rotation.reserve(4 * b.keyframes.size());
      std::array<float, 4> previous{0, 0, 0, 0};
      for (std::size_t k = 0; k < b.keyframes.size(); ++k) {
        const Vec3& p = b.keyframes[k].translation;
        translation.insert(translation.end(), {float(p.x()), float(p.y()), float(p.z())});
        std::array<float, 4> q = floatQuat(b.keyframes[k].rotation);
        const float dot = q[0] * previous[0] + q[1] * previous[1] + q[2] * previous[2] + q[3] * previous[3];
        if (k > 0 && dot < 0.0f)
          for (float& c : q) c = -c;
        rotation.insert(rotation.end(), q.begin(), q.end());
        previous = q;
      }
      const int tAcc = addFloatAccessor(model, translation, 3, TINYGLTF_TYPE_VEC3, 0, false);
      const int rAcc = addFloatAccessor(model, rotation, 4, TINYGLTF_TYPE_VEC4, 0, false);
      for (const auto& [path, output] : {std::pair<const char*, int>{"translation", tAcc}, {"rotation", rAcc}}) {
        tinygltf::AnimationSampler sampler;
        sampler.input = input;
        sampler.output = output;
        sampler.interpolation = "LINEAR";
        anim.samplers.push_back(std::move(sampler));
        tinygltf::AnimationChannel channel;
        channel.sampler = int(anim.samplers.size() - 1);
        channel.target_node = int(i);
        channel.target_path = path;
        anim.channels.push_back(std::move(channel));
      }
    }
    if (!anim.channels.empty()) model.animations.push_back(std::move(anim));
  }
  // The BIN chunk length must be a multiple of 4; TinyGLTF pads the chunk, and byteLength stays
  // the true data length as the specification allows.
  std::ostringstream stream(std::ios::binary);
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, stream, false, true))
    throw Error(ErrorCode::kFileWriteFailed, "glTF export: TinyGLTF could not encode the scene");
  return std::move(stream).str();
}

void saveGlb(const std::filesystem::path& path, const GltfScene& scene) { writeFileAtomically(path, encodeGlb(scene)); }

}  // namespace clod
