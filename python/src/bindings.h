#pragma once
// What the two translation units of the Python module share: the Python-side objects that wrap
// clod's meshes and bakes, NumPy argument checking, and the registration functions.
//
// Conventions of the bindings (docs/python.md):
//  * arrays in and out are NumPy arrays in structure-of-arrays form ((N, 3) float64 for points,
//    one array per field of a result), never lists of per-element Python objects;
//  * every array argument is checked before any C++ code sees it (kind, shape, finiteness) and
//    refused with clod.InvalidArgumentError naming the argument, the row and the value: clod's
//    own preconditions are CLOD_ASSERTs, compiled out in Release, so nothing unchecked may pass;
//  * long-running calls release the GIL; parallel ones use TBB like the library does.

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "clod/bake.h"
#include "clod/collision_body.h"
#include "clod/error.h"
#include "clod/math.h"
#include "clod/mesh.h"
#include "clod/mesh_validation.h"
#include "clod/proximity.h"

namespace clod::python {

namespace py = pybind11;

/// An array argument as the caller passed it (an ndarray, a list, a tuple...): the bindings check
/// and convert it themselves (toDoubleArray, requirePoints, parsePose). Its own type caster only
/// gives signatures a readable name, so help() shows "numpy.typing.ArrayLike", not "handle".
struct ArrayLike {
  py::object value;
  operator py::handle() const { return value; }
};

/// A C-contiguous float64 NumPy array (what every numeric argument is converted to).
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// Throws clod::Error(kInvalidArgument) with `message` (becomes clod.InvalidArgumentError).
[[noreturn]] void invalidArgument(const std::string& message);

/// `obj` as a C-contiguous float64 array. Accepts anything NumPy turns into an array of real
/// numbers (float or integer dtypes, lists); refuses bool, complex, object and string dtypes
/// and non-array-likes, naming `name` and what it got. Shape is not checked here.
DoubleArray toDoubleArray(py::handle obj, const char* name);

/// "(5, 2)": the shape of an array as Python prints it.
std::string shapeText(const py::array& array);

/// An (N, 3) array of finite real numbers with |x| <= 1e150 (MeshDistance's range), as float64.
/// Refuses other shapes ("points: expected shape (N, 3), got (5, 2)") and the first non-finite
/// or out-of-range row ("points[17] = (nan, 0, 1) is not finite").
DoubleArray requirePoints(py::handle obj, const char* name);

/// Checks that every value of `array` is finite, naming the first bad row (rows of `rowWidth`).
void requireFinite(const DoubleArray& array, const char* name, std::size_t rowWidth);

/// A pose from Python: a (7,) array "tx ty tz qw qx qy qz" (the CLI's form; the quaternion is
/// normalised and must not be zero) or a (4, 4) homogeneous matrix whose upper-left 3x3 is a
/// rotation (orthonormal within 1e-6, determinant +1) and whose last row is (0, 0, 0, 1).
Pose parsePose(py::handle obj, const char* name);
/// One pose or many: (7,), (4, 4), (P, 7) or (P, 4, 4) -> P poses (1 for a single pose).
std::vector<Pose> parsePoses(py::handle obj, const char* name);

/// clod.Mesh: an immutable triangle mesh, its validation report, and (built on first use) its
/// exact distance structure.
struct PyMesh {
  std::shared_ptr<const TriangleMesh> mesh;
  MeshReport report;
  // What the loader said (Mesh.load); empty / zero for meshes built from arrays.
  std::vector<std::string> warnings;
  std::string source;
  bool flipped = false;
  std::uint32_t importedVertexCount = 0;
  std::uint32_t weldedVertexCount = 0;
  double weldToleranceAbs = 0.0;

  /// The MeshDistance of `mesh` (pseudonormal/automatic sign, or forced winding numbers), built
  /// the first time it is asked for. Call without the GIL (building takes O(T log T)).
  const MeshDistance& distance(bool forceWindingNumber) const;

private:
  mutable std::mutex distanceMutex_;
  mutable std::shared_ptr<const MeshDistance> distance_[2];
};

/// Wraps a mesh the caller has checked (requireValidMesh or loadMesh).
std::shared_ptr<PyMesh> makePyMesh(TriangleMesh mesh, MeshReport report);

/// How a bake was built (only for bakes made by clod.bake, not loaded ones).
struct BakeBuildInfo {
  std::vector<SphereTreeLevelFit> levelFit;
  SignMethod signMethod = SignMethod::kPseudonormal;
  BakeTimings timings;
  ContactTreeBuildStats contactTreeStats;
};

/// clod.Bake: a bake's contents and the collision body made from them (shared by every query
/// and world body that uses it; immutable).
struct PyBake {
  std::shared_ptr<const BakeContents> contents;
  std::shared_ptr<const CollisionBody> body;
  std::optional<BakeBuildInfo> buildInfo;
};

/// Wraps contents (builds the collision body; no GIL needed).
std::shared_ptr<PyBake> makePyBake(BakeContents contents, std::optional<BakeBuildInfo> info);

/// module.cpp: errors, version, Mesh, Bake, bake(), closest points.
void bindCore(py::module_& m);
/// bind_dynamics.cpp: query, query_batch, World, experiment.
void bindDynamics(py::module_& m);

}  // namespace clod::python

namespace pybind11::detail {
template <>
struct type_caster<clod::python::ArrayLike> {
  PYBIND11_TYPE_CASTER(clod::python::ArrayLike, const_name("numpy.typing.ArrayLike"));
  bool load(handle source, bool) {
    value.value = reinterpret_borrow<object>(source);
    return true;
  }
  static handle cast(const clod::python::ArrayLike& array, return_value_policy, handle) { return array.value.inc_ref(); }
};
}  // namespace pybind11::detail
