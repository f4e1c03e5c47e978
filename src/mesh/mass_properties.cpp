#include "clod/mass_properties.h"

#include <cmath>
#include <numbers>
#include <string>

#include "clod/error.h"
#include "clod/mesh_validation.h"

namespace clod {

MassProperties computeMassProperties(const TriangleMesh& mesh, double density) {
  if (!(density > 0.0) || !std::isfinite(density))
    throw Error(ErrorCode::kInvalidArgument, "density " + std::to_string(density) + " is not a positive finite number");
  const MeshReport report = requireValidMesh(mesh);
  if (!report.closed)
    throw Error(ErrorCode::kUnsupportedMesh,
                "mass properties need a closed mesh, this one has " + std::to_string(report.boundaryEdges) +
                    " boundary and " + std::to_string(report.nonManifoldEdges) + " non-manifold edges");
  if (!report.consistentlyOriented)
    throw Error(ErrorCode::kUnsupportedMesh, "mass properties need a consistently oriented mesh, " +
                                                 std::to_string(report.inconsistentEdges) + " edges disagree");

  // Integrals over the solid as sums of signed tetrahedra (o, a, b, c), with o the box centre.
  // For a tetrahedron with corners p0..p3 and volume V (Tonon 2004):
  //   integral x_i dV      = V/4  * sum_p p_i
  //   integral x_i x_j dV  = V/20 * (sum_p p_i p_j + (sum_p p_i)(sum_p p_j))
  // and p0 = o = 0 in local coordinates drops out of both sums.
  const Vec3 o = report.bounds.center();
  double sixVolume = 0.0;
  Vec3 first = Vec3::Zero();    // 24 * integral x dV
  Mat3 second = Mat3::Zero();   // 120 * integral x x^T dV
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) {
    const Vec3 a = mesh.corner(t, 0) - o;
    const Vec3 b = mesh.corner(t, 1) - o;
    const Vec3 c = mesh.corner(t, 2) - o;
    const double det = a.dot(b.cross(c));  // 6 * signed tetrahedron volume
    const Vec3 s = a + b + c;
    sixVolume += det;
    first += det * s;
    second += det * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  double volume = sixVolume / 6.0;
  Vec3 moment = first / 24.0;
  Mat3 covariance = second / 120.0;
  if (volume < 0.0) {
    // Inside-out: every integral changes sign with the orientation; the solid is the same.
    volume = -volume;
    moment = -moment;
    covariance = -covariance;
  }
  // A "closed" mesh can still be flat (two coincident sheets) or numerically empty.
  const double diagonal = report.bounds.diagonal();
  if (!(volume > 1e-12 * diagonal * diagonal * diagonal))
    throw Error(ErrorCode::kUnsupportedMesh,
                "the closed mesh encloses no volume (" + std::to_string(volume) + "): it is flat");

  MassProperties result;
  result.volume = volume;
  result.mass = density * volume;
  const Vec3 centroidLocal = moment / volume;
  result.centerOfMass = o + centroidLocal;
  // Covariance about the centre of mass (parallel-axis shift), then I = tr(C) Id - C.
  const Mat3 cov = density * (covariance - volume * centroidLocal * centroidLocal.transpose());
  result.inertia = cov.trace() * Mat3::Identity() - cov;
  result.inertia = 0.5 * (result.inertia + result.inertia.transpose()).eval();
  return result;
}

MassProperties computeMassPropertiesOrBoundingBox(const TriangleMesh& mesh, double density) {
  try {
    return computeMassProperties(mesh, density);
  } catch (const Error& e) {
    if (e.code() != ErrorCode::kUnsupportedMesh) throw;
  }
  const Aabb box = mesh.bounds();
  const Vec3 e = box.extent();
  MassProperties mp;
  mp.volume = e.x() * e.y() * e.z();
  mp.mass = density * mp.volume;
  mp.centerOfMass = box.center();
  mp.inertia = Mat3::Zero();  // solid box about its centre: m/12 (b^2 + c^2) per axis
  mp.inertia(0, 0) = mp.mass / 12.0 * (e.y() * e.y() + e.z() * e.z());
  mp.inertia(1, 1) = mp.mass / 12.0 * (e.x() * e.x() + e.z() * e.z());
  mp.inertia(2, 2) = mp.mass / 12.0 * (e.x() * e.x() + e.y() * e.y());
  return mp;
}

MassProperties ballMassProperties(double radius, double density) {
  if (!(radius > 0.0 && std::isfinite(radius)) || !(density > 0.0 && std::isfinite(density)))
    throw Error(ErrorCode::kInvalidArgument, "ball radius and density must be > 0 and finite");
  MassProperties mp;
  mp.volume = 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
  mp.mass = density * mp.volume;
  mp.inertia = Mat3::Identity() * (0.4 * mp.mass * radius * radius);
  return mp;
}

}  // namespace clod
