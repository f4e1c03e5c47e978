// Building closest feature maps: one exact closest-feature query per sample point of every
// sphere, against only the triangles that sphere is responsible for (the paper's "closest feature
// of the part of the mesh the sphere bounds").
#include <cmath>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "clod/closest_feature_map.h"
#include "clod/error.h"
#include "clod/normal_encoding.h"
#include "clod/proximity.h"

namespace clod {

namespace {

[[noreturn]] void invalid(const std::string& what) {
  throw Error(ErrorCode::kInvalidArgument, "buildClosestFeatureMap: " + what);
}

std::string str(std::uint64_t value) { return std::to_string(value); }

void checkTree(const SphereTree& tree, std::uint32_t triangleCount) {
  const std::size_t n = tree.radius.size();
  if (n == 0 || tree.levelOffsets.size() < 2 || tree.levelOffsets.back() != n || tree.centerX.size() != n ||
      tree.centerY.size() != n || tree.centerZ.size() != n || tree.triangleOffsets.size() != n + 1 ||
      tree.triangleOffsets.back() != tree.triangleList.size()) {
    invalid("the sphere-tree's arrays are inconsistent");
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (tree.triangleOffsets[i + 1] <= tree.triangleOffsets[i]) invalid("sphere " + str(i) + " is responsible for no triangle");
  }
  for (std::size_t k = 0; k < tree.triangleList.size(); ++k) {
    if (tree.triangleList[k] >= triangleCount) {
      invalid("triangleList[" + str(k) + "] = " + str(tree.triangleList[k]) + " >= mesh triangle count " + str(triangleCount));
    }
  }
}

// Area-weighted mean of face normals = normalised sum of the (unnormalised) cross products.
// Zero when the sum is negligible against the total area (normals cancel, e.g. a closed
// component entirely inside the sphere): then no direction is meaningful.
Vec3 averageFaceNormal(const TriangleMesh& mesh, std::span<const std::uint32_t> triangles) {
  Vec3 sum = Vec3::Zero();
  double area = 0.0;
  for (std::uint32_t t : triangles) {
    const Triangle& tri = mesh.triangles[t];
    const Vec3& a = mesh.vertices[tri[0]];
    const Vec3 cross = (mesh.vertices[tri[1]] - a).cross(mesh.vertices[tri[2]] - a);
    sum += cross;
    area += cross.norm();
  }
  const double length = sum.norm();
  return length > 1e-9 * area && length > 0.0 ? Vec3(sum / length) : Vec3::Zero();
}

}  // namespace

ClosestFeatureMap buildClosestFeatureMap(const MeshDistance& mesh, const SphereTree& tree,
                                         const ClosestFeatureMapSettings& settings) {
  validateClosestFeatureMapSettings(settings);
  checkTree(tree, mesh.mesh().triangleCount());
  const std::uint32_t levels = tree.levelCount();
  const std::uint32_t spheres = tree.sphereCount();

  ClosestFeatureMapData data;
  data.settings = settings;
  std::vector<SphereSampling> samplings;
  for (std::uint32_t l = 0; l < levels; ++l) {
    const int stacks = closestFeatureMapStacks(settings, static_cast<int>(l));
    data.levelStacks.push_back(static_cast<std::uint32_t>(stacks));
    if (l > 0 && data.levelStacks[l - 1] == static_cast<std::uint32_t>(stacks)) {
      samplings.push_back(samplings.back());
    } else {
      samplings.push_back(SphereSampling::buildForStacks(settings.scheme, stacks));
    }
  }

  // Per sphere, the codes of all its samples (or its one code). Spheres are independent.
  const bool wide = settings.codec == NormalCodec::kOctahedral32;
  std::vector<std::vector<std::uint32_t>> codes(spheres);
  std::vector<std::uint8_t> single(spheres, 0);
  std::vector<Vec3> averages(spheres);
  const double cosSame = std::cos(kSingleNormalAngle);
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, spheres, 4), [&](const tbb::blocked_range<std::uint32_t>& range) {
    std::vector<Vec3> normals;
    for (std::uint32_t i = range.begin(); i != range.end(); ++i) {
      std::uint32_t level = 0;
      while (tree.levelEnd(level) <= i) ++level;
      const SphereSampling& sampling = samplings[level];
      const std::span<const std::uint32_t> triangles = tree.triangles(i);
      const Vec3 centre = tree.center(i);
      const double radius = tree.radius[i];
      normals.resize(sampling.size());
      bool allSame = true;
      for (std::uint32_t k = 0; k < sampling.size(); ++k) {
        normals[k] = mesh.closestPointAmong(centre + radius * sampling.direction(k), triangles).normal;
        allSame = allSame && normals[k].dot(normals[0]) >= cosSame;
      }
      single[i] = allSame ? 1 : 0;
      const std::size_t stored = allSame ? 1 : normals.size();
      codes[i].resize(stored);
      for (std::size_t k = 0; k < stored; ++k) {
        codes[i][k] = wide ? encodeOctahedral32(normals[k]) : encodeOctahedral16(normals[k]);
      }
      averages[i] = averageFaceNormal(mesh.mesh(), triangles);
    }
  });

  std::uint64_t total = 0;
  for (const auto& c : codes) total += c.size();
  if (total >= 0xffffffffull) invalid("the map would hold " + str(total) + " normals (more than 2^32 - 1)");
  data.sphereOffset.reserve(spheres);
  data.sphereSingle = std::move(single);
  if (wide) data.codes32.reserve(total); else data.codes16.reserve(total);
  data.averageNormals.reserve(3ull * spheres);
  std::uint32_t offset = 0;
  for (std::uint32_t i = 0; i < spheres; ++i) {
    data.sphereOffset.push_back(offset);
    offset += static_cast<std::uint32_t>(codes[i].size());
    for (std::uint32_t c : codes[i]) {
      if (wide) data.codes32.push_back(c); else data.codes16.push_back(static_cast<std::uint16_t>(c));
    }
    for (int a = 0; a < 3; ++a) data.averageNormals.push_back(static_cast<float>(averages[i][a]));
  }
  return ClosestFeatureMap::fromData(std::move(data), tree);
}

}  // namespace clod
