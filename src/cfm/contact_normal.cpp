#include "clod/contact_normal.h"

#include <string>

#include "clod/error.h"

namespace clod {

namespace {
constexpr ContactNormalModel kModels[] = {ContactNormalModel::kDingliana, ContactNormalModel::kAverage,
                                          ContactNormalModel::kClosestFeatureMap};
}  // namespace

std::span<const ContactNormalModel> allContactNormalModels() noexcept { return kModels; }

std::string_view contactNormalModelName(ContactNormalModel model) noexcept {
  switch (model) {
    case ContactNormalModel::kDingliana: return "dos";
    case ContactNormalModel::kAverage: return "average";
    case ContactNormalModel::kClosestFeatureMap: return "cfm";
  }
  return "unknown";
}

ContactNormalModel parseContactNormalModel(std::string_view name) {
  for (ContactNormalModel model : kModels) {
    if (name == contactNormalModelName(model)) return model;
  }
  throw Error(ErrorCode::kInvalidArgument, "unknown contact normal model '" + std::string(name) + "' (valid: dos, average, cfm)");
}

Vec3 contactNormal(ContactNormalModel model, const SphereTree& tree, const ClosestFeatureMap& maps,
                   std::uint32_t sphere, const Vec3& pointLocal) noexcept {
  CLOD_ASSERT(sphere < tree.sphereCount() && tree.sphereCount() == maps.sphereCount());
  const Vec3 offset = pointLocal - tree.center(sphere);
  if (model == ContactNormalModel::kClosestFeatureMap) return maps.normal(sphere, offset);
  if (model == ContactNormalModel::kAverage) {
    const Vec3 average = maps.averageNormal(sphere);
    if (average.squaredNorm() > 0.0) return average;
  }
  const double length = offset.norm();
  if (length > 1e-300) return offset / length;
  const Vec3 average = maps.averageNormal(sphere);
  return average.squaredNorm() > 0.0 ? average : Vec3::UnitZ();
}

}  // namespace clod
