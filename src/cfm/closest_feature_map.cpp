#include "clod/closest_feature_map.h"

#include <cmath>
#include <map>
#include <string>

#include "clod/error.h"
#include "clod/normal_encoding.h"

namespace clod {

namespace {

[[noreturn]] void invalid(const std::string& what) {
  throw Error(ErrorCode::kInvalidArgument, "closest feature map: " + what);
}

std::string str(std::uint64_t value) { return std::to_string(value); }

}  // namespace

std::string_view normalCodecName(NormalCodec codec) noexcept {
  switch (codec) {
    case NormalCodec::kOctahedral16: return "oct16";
    case NormalCodec::kOctahedral32: return "oct32";
  }
  return "unknown";
}

NormalCodec parseNormalCodec(std::string_view name) {
  if (name == "oct16") return NormalCodec::kOctahedral16;
  if (name == "oct32") return NormalCodec::kOctahedral32;
  throw Error(ErrorCode::kInvalidArgument, "unknown normal codec '" + std::string(name) + "' (valid: oct16, oct32)");
}

double normalCodecErrorBound(NormalCodec codec) noexcept {
  return octahedralErrorBound(codec == NormalCodec::kOctahedral16 ? 8 : 16);
}

int closestFeatureMapStacks(const ClosestFeatureMapSettings& settings, int level) noexcept {
  CLOD_ASSERT(settings.minStacks >= 1 && settings.minStacks <= settings.rootStacks && level >= 0);
  const int halved = stacksAtLevel(settings.rootStacks, level);
  return halved < settings.minStacks ? settings.minStacks : halved;
}

void validateClosestFeatureMapSettings(const ClosestFeatureMapSettings& s) {
  bool knownScheme = false;
  for (SamplingScheme scheme : allSamplingSchemes()) knownScheme = knownScheme || scheme == s.scheme;
  if (!knownScheme) invalid("unknown sampling scheme " + str(static_cast<std::uint32_t>(s.scheme)));
  if (s.codec != NormalCodec::kOctahedral16 && s.codec != NormalCodec::kOctahedral32) {
    invalid("unknown normal codec " + str(static_cast<std::uint32_t>(s.codec)));
  }
  const int maxStacks = maxSamplingResolution(SamplingScheme::kPolar);
  if (s.rootStacks < 1 || s.rootStacks > maxStacks) {
    invalid("root stacks " + std::to_string(s.rootStacks) + " outside [1, " + std::to_string(maxStacks) + "]");
  }
  if (s.minStacks < 1 || s.minStacks > s.rootStacks) {
    invalid("min stacks " + std::to_string(s.minStacks) + " outside [1, root stacks " + std::to_string(s.rootStacks) + "]");
  }
}

ClosestFeatureMap ClosestFeatureMap::fromData(ClosestFeatureMapData data, const SphereTree& tree) {
  const ClosestFeatureMapSettings& s = data.settings;
  validateClosestFeatureMapSettings(s);
  const std::uint32_t levels = tree.levelCount();
  const std::uint32_t spheres = tree.sphereCount();
  if (data.levelStacks.size() != levels) {
    invalid("levelStacks has " + str(data.levelStacks.size()) + " entries, the sphere-tree has " + str(levels) + " levels");
  }
  for (std::uint32_t l = 0; l < levels; ++l) {
    const int expected = closestFeatureMapStacks(s, static_cast<int>(l));
    if (data.levelStacks[l] != static_cast<std::uint32_t>(expected)) {
      invalid("levelStacks[" + str(l) + "] = " + str(data.levelStacks[l]) + ", the refinement rule gives " + std::to_string(expected));
    }
  }
  if (data.sphereOffset.size() != spheres) invalid("sphereOffset has " + str(data.sphereOffset.size()) + " entries, expected " + str(spheres));
  if (data.sphereSingle.size() != spheres) invalid("sphereSingle has " + str(data.sphereSingle.size()) + " entries, expected " + str(spheres));
  if (data.averageNormals.size() != 3ull * spheres) {
    invalid("averageNormals has " + str(data.averageNormals.size()) + " entries, expected " + str(3ull * spheres));
  }
  const bool wide = s.codec == NormalCodec::kOctahedral32;
  if (wide ? !data.codes16.empty() : !data.codes32.empty()) {
    invalid(std::string("the ") + (wide ? "16" : "32") + "-bit pool is not empty although the codec is " +
            std::string(normalCodecName(s.codec)));
  }
  const std::uint64_t pool = wide ? data.codes32.size() : data.codes16.size();

  ClosestFeatureMap map;
  // Samplings are shared by levels with the same stack count (deep levels all sit at minStacks).
  std::map<std::uint32_t, std::size_t> firstLevelWithStacks;
  map.samplings_.reserve(levels);
  for (std::uint32_t l = 0; l < levels; ++l) {
    auto [it, inserted] = firstLevelWithStacks.try_emplace(data.levelStacks[l], l);
    if (inserted) {
      map.samplings_.push_back(SphereSampling::buildForStacks(s.scheme, static_cast<int>(data.levelStacks[l])));
    } else {
      map.samplings_.push_back(map.samplings_[it->second]);
    }
  }
  map.sphereLevel_.resize(spheres);
  std::uint64_t expectedOffset = 0;
  for (std::uint32_t l = 0; l < levels; ++l) {
    for (std::uint32_t i = tree.levelBegin(l); i < tree.levelEnd(l); ++i) {
      map.sphereLevel_[i] = l;
      if (data.sphereSingle[i] > 1) invalid("sphereSingle[" + str(i) + "] = " + str(data.sphereSingle[i]) + " (must be 0 or 1)");
      if (data.sphereOffset[i] != expectedOffset) {
        invalid("sphereOffset[" + str(i) + "] = " + str(data.sphereOffset[i]) + ", expected " + str(expectedOffset) +
                " (spheres own consecutive pool ranges)");
      }
      expectedOffset += data.sphereSingle[i] ? 1u : map.samplings_[l].size();
    }
  }
  if (expectedOffset != pool) invalid("the spheres own " + str(expectedOffset) + " normals but the pool holds " + str(pool));
  for (std::uint32_t i = 0; i < spheres; ++i) {
    const Vec3 a(data.averageNormals[3 * i], data.averageNormals[3 * i + 1], data.averageNormals[3 * i + 2]);
    const double length = a.norm();
    // Stored as float: a unit vector's length is within ~1e-7 of 1 after rounding.
    if (!std::isfinite(length) || (length != 0.0 && std::abs(length - 1.0) > 1e-5)) {
      invalid("average normal of sphere " + str(i) + " has length " + std::to_string(length) + " (must be 0 or 1)");
    }
  }
  map.data_ = std::move(data);
  return map;
}

std::uint32_t ClosestFeatureMap::storedNormalCount(std::uint32_t sphere) const noexcept {
  CLOD_ASSERT(sphere < sphereCount());
  return data_.sphereSingle[sphere] ? 1u : samplings_[sphereLevel_[sphere]].size();
}

std::uint32_t ClosestFeatureMap::sampleIndex(std::uint32_t sphere, const Vec3& directionFromCentre) const noexcept {
  CLOD_ASSERT(sphere < sphereCount());
  if (data_.sphereSingle[sphere]) return 0;
  const double length = directionFromCentre.norm();
  // A zero or non-finite direction has no nearest sample; sample 0 is as good as any.
  if (!(length > 1e-300) || !std::isfinite(length)) return 0;
  return samplings_[sphereLevel_[sphere]].nearest(directionFromCentre / length);
}

Vec3 ClosestFeatureMap::storedNormal(std::uint32_t sphere, std::uint32_t sample) const noexcept {
  CLOD_ASSERT(sphere < sphereCount() && sample < storedNormalCount(sphere));
  const std::uint32_t at = data_.sphereOffset[sphere] + sample;
  return data_.settings.codec == NormalCodec::kOctahedral16 ? decodeOctahedral16(data_.codes16[at])
                                                             : decodeOctahedral32(data_.codes32[at]);
}

Vec3 ClosestFeatureMap::normal(std::uint32_t sphere, const Vec3& directionFromCentre) const noexcept {
  return storedNormal(sphere, sampleIndex(sphere, directionFromCentre));
}

Vec3 ClosestFeatureMap::averageNormal(std::uint32_t sphere) const noexcept {
  CLOD_ASSERT(sphere < sphereCount());
  const float* a = data_.averageNormals.data() + 3 * static_cast<std::size_t>(sphere);
  const Vec3 v(a[0], a[1], a[2]);
  // Stored as float; renormalise so callers get a unit vector to double precision.
  const double length = v.norm();
  return length > 0.0 ? Vec3(v / length) : Vec3::Zero();
}

std::size_t ClosestFeatureMap::poolSize() const noexcept {
  return data_.settings.codec == NormalCodec::kOctahedral16 ? data_.codes16.size() : data_.codes32.size();
}

std::size_t ClosestFeatureMap::poolBytes() const noexcept {
  return data_.codes16.size() * sizeof(std::uint16_t) + data_.codes32.size() * sizeof(std::uint32_t);
}

}  // namespace clod
