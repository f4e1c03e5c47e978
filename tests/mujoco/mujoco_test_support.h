#pragma once
// What the MuJoCo plug-in's tests share: models written as MJCF text with inline meshes.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "clod/mesh.h"
#include "clod/mujoco/collider.h"

namespace clod::test {

/// <mesh name=".." vertex=".." face=".."/> of a clod mesh (MuJoCo recentres it at its centroid
/// and turns it to its principal axes, and moves the geom's frame to match).
inline std::string inlineMesh(const std::string& name, const TriangleMesh& mesh) {
  std::ostringstream out;
  out.precision(17);
  out << "<mesh name=\"" << name << "\" vertex=\"";
  for (const Vec3& v : mesh.vertices) out << v.x() << ' ' << v.y() << ' ' << v.z() << ' ';
  out << "\" face=\"";
  for (const Triangle& t : mesh.triangles) out << t[0] << ' ' << t[1] << ' ' << t[2] << ' ';
  out << "\"/>";
  return out.str();
}

/// Writes `xml` to a file in the test's temporary folder and loads it.
inline mujoco::ModelPtr loadXmlText(const std::string& xml, const std::string& fileName) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "clod-mujoco-tests";
  std::filesystem::create_directories(dir);
  const std::filesystem::path path = dir / fileName;
  std::ofstream(path) << xml;
  return mujoco::loadModel(path);
}

/// World position of a body's frame.
inline Vec3 bodyPosition(const mjData* d, int body) {
  return Vec3(d->xpos[3 * body], d->xpos[3 * body + 1], d->xpos[3 * body + 2]);
}

}  // namespace clod::test
