// The Python module clod._clod, part one: errors, version, argument checking, Mesh (loading,
// validation report, mass properties, exact closest points in parallel), Bake (bake, load, save).
// Part two (query, World, experiments) is bind_dynamics.cpp; python/clod/ re-exports both.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "bindings.h"
#include "clod/mass_properties.h"
#include "clod/mesh_io.h"
#include "clod/primitives.h"
#include "clod/quaternion.h"
#include "clod/sphere_sampling.h"
#include "clod/version.h"

namespace clod::python {

// ---------------------------------------------------------------------------------------------
// Errors: clod::Error -> clod.Error (or a subclass that is also the matching built-in Python
// exception), with the code as attributes.

namespace {

PyObject* gError = nullptr;            // clod.Error(RuntimeError)
PyObject* gInvalidArgument = nullptr;  // clod.InvalidArgumentError(clod.Error, ValueError)
PyObject* gFileError = nullptr;        // clod.FileError(clod.Error, OSError)

PyObject* errorTypeFor(ErrorCode code) {
  switch (code) {
    case ErrorCode::kInvalidArgument: return gInvalidArgument;
    case ErrorCode::kFileNotFound:
    case ErrorCode::kFileUnreadable:
    case ErrorCode::kFileWriteFailed:
    case ErrorCode::kEmptyFile: return gFileError;
    default: return gError;
  }
}

void raiseClodError(const Error& error) {
  PyObject* type = errorTypeFor(error.code());
  py::object exception = py::reinterpret_borrow<py::object>(type)(error.what());
  exception.attr("code") = static_cast<int>(error.code());
  exception.attr("code_name") = std::string(errorCodeName(error.code()));
  PyErr_SetObject(type, exception.ptr());
}

}  // namespace

void invalidArgument(const std::string& message) { throw Error(ErrorCode::kInvalidArgument, message); }

// ---------------------------------------------------------------------------------------------
// Argument checking.

std::string shapeText(const py::array& array) {
  std::ostringstream text;
  text << "(";
  for (py::ssize_t i = 0; i < array.ndim(); ++i) text << (i ? ", " : "") << array.shape(i);
  text << (array.ndim() == 1 ? ",)" : ")");
  return text.str();
}

DoubleArray toDoubleArray(py::handle obj, const char* name) {
  if (obj.is_none()) invalidArgument(std::string(name) + ": expected an array of real numbers, got None");
  py::array array = py::array::ensure(obj);
  if (!array) {
    PyErr_Clear();
    invalidArgument(std::string(name) + ": expected an array of real numbers, got " +
                    std::string(py::str(py::type::of(obj).attr("__name__"))));
  }
  const char kind = array.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    invalidArgument(std::string(name) + ": expected an array of real numbers, got dtype " +
                    std::string(py::str(array.dtype())));
  }
  return DoubleArray::ensure(array);
}

void requireFinite(const DoubleArray& array, const char* name, std::size_t rowWidth) {
  const double* data = array.data();
  const std::size_t n = static_cast<std::size_t>(array.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (std::isfinite(data[i])) continue;
    const std::size_t row = i / rowWidth;
    std::ostringstream text;
    text << name << "[" << row << "] = (";
    for (std::size_t k = 0; k < rowWidth; ++k) text << (k ? ", " : "") << data[row * rowWidth + k];
    text << ") is not finite";
    invalidArgument(text.str());
  }
}

DoubleArray requirePoints(py::handle obj, const char* name) {
  DoubleArray points = toDoubleArray(obj, name);
  if (points.ndim() != 2 || points.shape(1) != 3) {
    invalidArgument(std::string(name) + ": expected shape (N, 3), got " + shapeText(points));
  }
  requireFinite(points, name, 3);
  // MeshDistance squares distances: keep them representable (proximity.h).
  const double* data = points.data();
  for (py::ssize_t i = 0; i < points.size(); ++i) {
    if (std::abs(data[i]) > 1e150) {
      invalidArgument(std::string(name) + "[" + std::to_string(i / 3) + "]: coordinate " + std::to_string(data[i]) +
                      " is out of range (|x| <= 1e150)");
    }
  }
  return points;
}

namespace {

Pose poseFromSeven(const double* v, const std::string& name) {
  for (int k = 0; k < 7; ++k) {
    if (!std::isfinite(v[k])) invalidArgument(name + ": pose value " + std::to_string(k) + " is not finite");
  }
  const std::optional<Quat> q = unitQuaternion(v[3], v[4], v[5], v[6]);
  if (!q) invalidArgument(name + ": the quaternion (qw, qx, qy, qz) is zero");
  Pose pose;
  pose.rotation = *q;
  pose.translation = Vec3(v[0], v[1], v[2]);
  return pose;
}

Pose poseFromMatrix(const double* m, const std::string& name) {
  for (int k = 0; k < 16; ++k) {
    if (!std::isfinite(m[k])) invalidArgument(name + ": matrix entry " + std::to_string(k) + " is not finite");
  }
  if (m[12] != 0.0 || m[13] != 0.0 || m[14] != 0.0 || m[15] != 1.0) {
    invalidArgument(name + ": the last row of a 4x4 pose must be (0, 0, 0, 1)");
  }
  Mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = m[i * 4 + j];
  // A rotation to the precision a user types or float32 carries: orthonormal within 1e-6.
  const double orthoError = (r.transpose() * r - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (orthoError > 1e-6 || r.determinant() < 0.0) {
    invalidArgument(name + ": the upper-left 3x3 of a 4x4 pose must be a rotation (orthonormal, determinant +1)");
  }
  Pose pose;
  pose.rotation = Quat(r).normalized();
  pose.translation = Vec3(m[3], m[7], m[11]);
  return pose;
}

}  // namespace

std::vector<Pose> parsePoses(py::handle obj, const char* name) {
  DoubleArray array = toDoubleArray(obj, name);
  const py::ssize_t nd = array.ndim();
  const double* data = array.data();
  std::vector<Pose> poses;
  if (nd == 1 && array.shape(0) == 7) {
    poses.push_back(poseFromSeven(data, name));
  } else if (nd == 2 && array.shape(0) == 4 && array.shape(1) == 4) {
    poses.push_back(poseFromMatrix(data, name));
  } else if (nd == 2 && array.shape(1) == 7) {
    poses.resize(static_cast<std::size_t>(array.shape(0)));
    for (std::size_t i = 0; i < poses.size(); ++i) poses[i] = poseFromSeven(data + 7 * i, std::string(name) + "[" + std::to_string(i) + "]");
  } else if (nd == 3 && array.shape(1) == 4 && array.shape(2) == 4) {
    poses.resize(static_cast<std::size_t>(array.shape(0)));
    for (std::size_t i = 0; i < poses.size(); ++i) poses[i] = poseFromMatrix(data + 16 * i, std::string(name) + "[" + std::to_string(i) + "]");
  } else {
    invalidArgument(std::string(name) + ": expected a pose (7,) \"tx ty tz qw qx qy qz\" or (4, 4), or P of them (P, 7) / (P, 4, 4); got shape " +
                    shapeText(array));
  }
  return poses;
}

Pose parsePose(py::handle obj, const char* name) {
  DoubleArray array = toDoubleArray(obj, name);
  if (!(array.ndim() == 1 && array.shape(0) == 7) && !(array.ndim() == 2 && array.shape(0) == 4 && array.shape(1) == 4)) {
    invalidArgument(std::string(name) + ": expected a pose of shape (7,) \"tx ty tz qw qx qy qz\" or (4, 4), got " + shapeText(array));
  }
  return parsePoses(array, name)[0];
}

// ---------------------------------------------------------------------------------------------
// Mesh.

const MeshDistance& PyMesh::distance(bool forceWindingNumber) const {
  std::lock_guard<std::mutex> lock(distanceMutex_);
  std::shared_ptr<const MeshDistance>& slot = distance_[forceWindingNumber ? 1 : 0];
  if (!slot) {
    MeshDistanceSettings settings;
    settings.forceWindingNumber = forceWindingNumber;
    slot = std::make_shared<const MeshDistance>(*mesh, settings);
  }
  return *slot;
}

std::shared_ptr<PyMesh> makePyMesh(TriangleMesh mesh, MeshReport report) {
  auto result = std::make_shared<PyMesh>();
  result->mesh = std::make_shared<const TriangleMesh>(std::move(mesh));
  result->report = std::move(report);
  return result;
}

namespace {

std::shared_ptr<PyMesh> meshFromArrays(py::handle verticesObj, py::handle facesObj) {
  DoubleArray vertices = toDoubleArray(verticesObj, "vertices");
  if (vertices.ndim() != 2 || vertices.shape(1) != 3) {
    invalidArgument("vertices: expected shape (N, 3), got " + shapeText(vertices));
  }
  py::array facesAny = py::array::ensure(facesObj);
  if (!facesAny) {
    PyErr_Clear();
    invalidArgument("faces: expected an array of integers, got " + std::string(py::str(py::type::of(facesObj).attr("__name__"))));
  }
  const char kind = facesAny.dtype().kind();
  // An empty list becomes float64: allow it (the mesh is then refused for having no triangles).
  if (kind != 'i' && kind != 'u' && !(facesAny.size() == 0)) {
    invalidArgument("faces: expected an integer array (vertex indices), got dtype " + std::string(py::str(facesAny.dtype())));
  }
  using IndexArray = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;
  IndexArray faces = IndexArray::ensure(facesAny);
  if (faces.size() == 0 && faces.ndim() == 1) faces = IndexArray(std::vector<py::ssize_t>{0, 3});
  if (faces.ndim() != 2 || faces.shape(1) != 3) invalidArgument("faces: expected shape (M, 3), got " + shapeText(faces));

  TriangleMesh mesh;
  mesh.vertices.resize(static_cast<std::size_t>(vertices.shape(0)));
  const double* v = vertices.data();
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) mesh.vertices[i] = Vec3(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
  mesh.triangles.resize(static_cast<std::size_t>(faces.shape(0)));
  const std::int64_t* f = faces.data();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::int64_t index = f[3 * t + static_cast<std::size_t>(k)];
      if (index < 0 || index > std::int64_t(UINT32_MAX) - 1) {
        throw Error(ErrorCode::kIndexOutOfRange, "faces[" + std::to_string(t) + "]: vertex index " + std::to_string(index) +
                                                     " out of range [0, " + std::to_string(mesh.vertices.size()) + ")");
      }
      mesh.triangles[t][static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(index);
    }
  }
  MeshReport report;
  {
    py::gil_scoped_release release;
    report = requireValidMesh(mesh);  // NaN vertices, indices >= N, no or only degenerate triangles
  }
  return makePyMesh(std::move(mesh), std::move(report));
}

std::shared_ptr<PyMesh> loadPyMesh(const std::string& path, double weldToleranceRel, bool orientOutward) {
  MeshLoadOptions options;
  options.weldToleranceRel = weldToleranceRel;
  options.orientOutward = orientOutward;
  LoadedMesh loaded;
  {
    py::gil_scoped_release release;
    loaded = loadMesh(path, options);
  }
  auto result = makePyMesh(std::move(loaded.mesh), std::move(loaded.report));
  result->warnings = std::move(loaded.warnings);
  result->source = path;
  result->flipped = loaded.flipped;
  result->importedVertexCount = loaded.importedVertexCount;
  result->weldedVertexCount = loaded.weldedVertexCount;
  result->weldToleranceAbs = loaded.weldToleranceAbs;
  return result;
}

py::array vec3Array(const Vec3& v) {
  py::array_t<double> out(3);
  for (int k = 0; k < 3; ++k) out.mutable_data()[k] = v[k];
  return out;
}

py::array mat3Array(const Mat3& m) {
  py::array_t<double> out({3, 3});
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out.mutable_data()[i * 3 + j] = m(i, j);
  return out;
}

py::dict inspectMesh(const PyMesh& m) {
  const MeshReport& r = m.report;
  py::dict out;
  out["vertices"] = r.vertexCount;
  out["triangles"] = r.triangleCount;
  out["closed"] = r.closed;
  out["consistently_oriented"] = r.consistentlyOriented;
  out["boundary_edges"] = r.boundaryEdges;
  out["nonmanifold_edges"] = r.nonManifoldEdges;
  out["nonmanifold_vertices"] = r.nonManifoldVertices;
  out["degenerate_triangles"] = r.degenerateTriangles;
  out["duplicate_triangles"] = r.duplicateTriangles;
  out["unreferenced_vertices"] = r.unreferencedVertices;
  out["components"] = r.components;
  out["inconsistent_edges"] = r.inconsistentEdges;
  out["edges"] = r.edgeCount;
  out["bbox_min"] = vec3Array(r.bounds.min);
  out["bbox_max"] = vec3Array(r.bounds.max);
  out["bbox_diagonal"] = r.bounds.diagonal();
  double area = 0.0;
  for (std::uint32_t t = 0; t < m.mesh->triangleCount(); ++t) area += m.mesh->triangleArea(t);
  out["surface_area"] = area;
  out["signed_volume"] = r.signedVolume ? py::object(py::float_(*r.signedVolume)) : py::object(py::none());
  out["usable"] = r.usable();
  py::list issues;
  for (const MeshIssue& issue : r.issues) {
    py::dict entry;
    entry["fatal"] = issue.fatal ? py::object(py::str(std::string(errorCodeName(*issue.fatal)))) : py::object(py::none());
    entry["message"] = issue.message;
    issues.append(entry);
  }
  out["issues"] = issues;
  out["warnings"] = m.warnings;
  out["flipped"] = m.flipped;
  out["imported_vertices"] = m.importedVertexCount;
  out["welded_vertices"] = m.weldedVertexCount;
  out["weld_tolerance"] = m.weldToleranceAbs;
  return out;
}

py::dict massPropertiesDict(const PyMesh& m, double density, bool boundingBoxFallback) {
  MassProperties p;
  {
    py::gil_scoped_release release;
    p = boundingBoxFallback ? computeMassPropertiesOrBoundingBox(*m.mesh, density) : computeMassProperties(*m.mesh, density);
  }
  py::dict out;
  out["volume"] = p.volume;
  out["mass"] = p.mass;
  out["center_of_mass"] = vec3Array(p.centerOfMass);
  out["inertia"] = mat3Array(p.inertia);
  return out;
}

/// Result of Mesh.closest: one array per field, row i for points[i].
struct ClosestResult {
  py::array point, normal, distance, signedDistance, featureType, featureIndex, triangle;
  std::string signMethod;
};

ClosestResult closestPoints(const PyMesh& m, const ArrayLike& pointsObj, const std::string& sign) {
  if (sign != "auto" && sign != "winding_number") invalidArgument("sign: expected \"auto\" or \"winding_number\", got \"" + sign + "\"");
  const DoubleArray points = requirePoints(pointsObj, "points");
  const std::size_t n = static_cast<std::size_t>(points.shape(0));
  const py::ssize_t rows = static_cast<py::ssize_t>(n);
  py::array_t<double> point({rows, py::ssize_t(3)}), normal({rows, py::ssize_t(3)}), distance(rows), signedDistance(rows);
  py::array_t<std::uint8_t> featureType(rows);
  py::array_t<std::uint32_t> featureIndex(rows), triangle(rows);
  const double* in = points.data();
  double* outPoint = point.mutable_data();
  double* outNormal = normal.mutable_data();
  double* outDistance = distance.mutable_data();
  double* outSigned = signedDistance.mutable_data();
  std::uint8_t* outType = featureType.mutable_data();
  std::uint32_t* outIndex = featureIndex.mutable_data();
  std::uint32_t* outTriangle = triangle.mutable_data();
  SignMethod method;
  {
    py::gil_scoped_release release;
    const MeshDistance& d = m.distance(sign == "winding_number");
    method = d.signMethod();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 64), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t i = range.begin(); i != range.end(); ++i) {
        const MeshDistance::Signed r = d.signedQuery(Vec3(in[3 * i], in[3 * i + 1], in[3 * i + 2]));
        for (int k = 0; k < 3; ++k) {
          outPoint[3 * i + k] = r.closest.point[k];
          outNormal[3 * i + k] = r.closest.normal[k];
        }
        outDistance[i] = r.closest.distance;
        outSigned[i] = r.signedDistance;
        outType[i] = static_cast<std::uint8_t>(r.closest.feature.type);
        outIndex[i] = r.closest.feature.index;
        outTriangle[i] = r.closest.triangle;
      }
    });
  }
  return {point, normal, distance, signedDistance, featureType, featureIndex, triangle, signMethodName(method)};
}

/// A read-only NumPy view of `data` kept alive by `owner`.
template <typename T>
py::array readOnlyView(const T* data, std::vector<py::ssize_t> shape, py::handle owner) {
  py::array_t<T> view(shape, data, owner);
  py::detail::array_proxy(view.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return view;
}

// ---------------------------------------------------------------------------------------------
// Bake.

std::shared_ptr<PyBake> bakePyMesh(const PyMesh& mesh, const std::string& sphereTree, std::uint32_t branching,
                                   std::uint32_t levels, std::uint32_t medialSamples, bool closestFeatureMap,
                                   const std::string& sampling, int stacks, int minStacks, const std::string& normalCodec,
                                   bool contactTree, double sdfError, std::uint32_t sdfDepth, bool measureFit,
                                   const std::string& sourceName) {
  BakeSettings settings;
  settings.sphereTree.method = parseSphereTreeMethod(sphereTree);
  settings.sphereTree.branching = branching;
  settings.sphereTree.depth = levels;
  settings.sphereTree.medialSamples = medialSamples;
  settings.buildClosestFeatureMap = closestFeatureMap;
  settings.closestFeatureMap.scheme = parseSamplingScheme(sampling);
  settings.closestFeatureMap.rootStacks = stacks;
  settings.closestFeatureMap.minStacks = minStacks;
  settings.closestFeatureMap.codec = parseNormalCodec(normalCodec);
  settings.buildContactTree = contactTree;
  settings.contactTree.errorRel = sdfError;
  settings.contactTree.maxDepth = sdfDepth;
  settings.measureFit = measureFit;
  settings.sourceName = sourceName.empty() ? mesh.source : sourceName;
  if (!(sdfError > 0.0) || !std::isfinite(sdfError)) invalidArgument("sdf_error: must be finite and > 0, got " + std::to_string(sdfError));
  py::gil_scoped_release release;
  BakeResult result = bakeMesh(*mesh.mesh, settings);
  BakeBuildInfo info{std::move(result.levelFit), result.signMethod, result.timings, result.contactTreeStats};
  return makePyBake(std::move(result.contents), std::move(info));
}

py::bytes bakeToBytes(const PyBake& bake) {
  std::vector<std::byte> bytes;
  {
    py::gil_scoped_release release;
    bytes = encodeBake(*bake.contents);
  }
  return py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

std::shared_ptr<PyBake> bakeFromBytes(const py::bytes& data) {
  const std::string_view view(data);
  const auto* begin = reinterpret_cast<const std::byte*>(view.data());
  py::gil_scoped_release release;
  return makePyBake(decodeBake(std::span<const std::byte>(begin, view.size())), std::nullopt);
}

py::object bakeReport(const PyBake& bake) {
  if (!bake.buildInfo) return py::none();
  const BakeBuildInfo& info = *bake.buildInfo;
  py::dict out;
  py::list levels;
  for (std::size_t l = 0; l < info.levelFit.size(); ++l) {
    py::dict level;
    level["level"] = l;
    level["spheres"] = info.levelFit[l].spheres;
    level["fit_mean"] = info.levelFit[l].fitMean;
    level["fit_max"] = info.levelFit[l].fitMax;
    levels.append(level);
  }
  out["levels"] = levels;
  out["sign_method"] = signMethodName(info.signMethod);
  out["build_seconds"] = info.timings.buildSeconds;
  out["distance_seconds"] = info.timings.distanceSeconds;
  out["sphere_tree_seconds"] = info.timings.sphereTreeSeconds;
  out["fit_seconds"] = info.timings.fitSeconds;
  out["cfm_seconds"] = info.timings.cfmSeconds;
  out["contact_tree_seconds"] = info.timings.contactTreeSeconds;
  out["sdf_cells"] = info.contactTreeStats.nodes;
  out["sdf_leaves"] = info.contactTreeStats.leaves;
  out["sdf_leaves_above_error"] = info.contactTreeStats.leavesAboveError;
  return out;
}

py::tuple bakeSpheres(const PyBake& bake, std::int64_t level) {
  const SphereTree& tree = bake.contents->sphereTree;
  std::uint32_t begin = 0, end = tree.sphereCount();
  if (level >= 0) {
    if (level >= std::int64_t(tree.levelCount())) {
      invalidArgument("level " + std::to_string(level) + ": the sphere-tree has levels 0.." + std::to_string(tree.levelCount() - 1));
    }
    begin = tree.levelBegin(static_cast<std::uint32_t>(level));
    end = tree.levelEnd(static_cast<std::uint32_t>(level));
  } else if (level != -1) {
    invalidArgument("level " + std::to_string(level) + ": must be >= 0 (or -1 for every level)");
  }
  const py::ssize_t n = end - begin;
  py::array_t<double> centers({n, py::ssize_t(3)}), radii(n);
  for (std::uint32_t i = begin; i < end; ++i) {
    centers.mutable_data()[3 * (i - begin)] = tree.centerX[i];
    centers.mutable_data()[3 * (i - begin) + 1] = tree.centerY[i];
    centers.mutable_data()[3 * (i - begin) + 2] = tree.centerZ[i];
    radii.mutable_data()[i - begin] = tree.radius[i];
  }
  return py::make_tuple(centers, radii);
}

}  // namespace

std::shared_ptr<PyBake> makePyBake(BakeContents contents, std::optional<BakeBuildInfo> info) {
  auto result = std::make_shared<PyBake>();
  auto shared = std::make_shared<const BakeContents>(std::move(contents));
  auto body = std::make_shared<CollisionBody>(CollisionBody::fromBake(*shared));
  if (body->name().empty()) body->setName("bake");
  result->contents = std::move(shared);
  result->body = std::move(body);
  result->buildInfo = std::move(info);
  return result;
}

// ---------------------------------------------------------------------------------------------

void bindCore(py::module_& mod) {
  // Exceptions. Created with the C API so the subclasses can also derive from ValueError/OSError.
  gError = PyErr_NewExceptionWithDoc(
      "clod.Error",
      "An error of clod: bad outside data (files, meshes, scenes, arguments).\n\n"
      "Attributes: code (int, clod::ErrorCode, stable), code_name (str, e.g. \"non_finite_vertex\").\n"
      "str(e) is clod's message, which names the culprit.",
      PyExc_RuntimeError, nullptr);
  py::tuple invalidBases = py::make_tuple(py::handle(gError), py::handle(PyExc_ValueError));
  gInvalidArgument = PyErr_NewExceptionWithDoc(
      "clod.InvalidArgumentError",
      "clod.Error with code invalid_argument: an argument, option or array out of its documented range "
      "(wrong shape or dtype, NaN, unknown name). Also a ValueError.",
      invalidBases.ptr(), nullptr);
  py::tuple fileBases = py::make_tuple(py::handle(gError), py::handle(PyExc_OSError));
  gFileError = PyErr_NewExceptionWithDoc(
      "clod.FileError",
      "clod.Error for files: file_not_found, file_unreadable, file_write_failed, empty_file. Also an OSError.",
      fileBases.ptr(), nullptr);
  mod.add_object("Error", py::handle(gError));
  mod.add_object("InvalidArgumentError", py::handle(gInvalidArgument));
  mod.add_object("FileError", py::handle(gFileError));
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      raiseClodError(e);
    }
  });
  py::dict codes;
  for (int c = static_cast<int>(ErrorCode::kInvalidArgument); c <= static_cast<int>(ErrorCode::kResourceLimit); ++c) {
    codes[py::str(std::string(errorCodeName(static_cast<ErrorCode>(c))))] = c;
  }
  mod.attr("error_codes") = codes;
  mod.attr("__version__") = clod::version();

  py::class_<ClosestResult>(mod, "ClosestResult",
                            "Exact closest points of a mesh to K query points (Mesh.closest). Every field is an\n"
                            "array with one row per query point, in the order of the points.")
      .def_readonly("point", &ClosestResult::point, "(K, 3) float64: closest point on the surface")
      .def_readonly("normal", &ClosestResult::normal,
                    "(K, 3) float64: outward unit normal of the closest feature (face normal, or the angle-weighted\n"
                    "pseudonormal of an edge or vertex); zero only where the feature has no direction")
      .def_readonly("distance", &ClosestResult::distance, "(K,) float64: unsigned distance |query - point|")
      .def_readonly("signed_distance", &ClosestResult::signedDistance, "(K,) float64: signed distance, negative inside")
      .def_readonly("feature_type", &ClosestResult::featureType,
                    "(K,) uint8: kind of the closest feature, FEATURE_VERTEX (0), FEATURE_EDGE (1) or FEATURE_FACE (2)")
      .def_readonly("feature_index", &ClosestResult::featureIndex,
                    "(K,) uint32: index of that feature: a vertex, an edge of the mesh's edge table (Mesh.edges), or a triangle")
      .def_readonly("triangle", &ClosestResult::triangle, "(K,) uint32: a triangle containing the closest point")
      .def_readonly("sign_method", &ClosestResult::signMethod,
                    "\"pseudonormal\" (closed, consistently oriented manifold meshes) or \"winding_number\"")
      .def("__len__", [](const ClosestResult& r) { return r.distance.shape(0); })
      .def("__repr__", [](const ClosestResult& r) {
        return "<clod.ClosestResult of " + std::to_string(r.distance.shape(0)) + " points, sign " + r.signMethod + ">";
      });
  mod.attr("FEATURE_VERTEX") = static_cast<int>(FeatureType::kVertex);
  mod.attr("FEATURE_EDGE") = static_cast<int>(FeatureType::kEdge);
  mod.attr("FEATURE_FACE") = static_cast<int>(FeatureType::kFace);

  py::class_<PyMesh, std::shared_ptr<PyMesh>> meshClass(
      mod, "Mesh",
      "An immutable triangle mesh (counter-clockwise triangles seen from outside, 32-bit indices).\n\n"
      "Mesh(vertices, faces) builds one from arrays: vertices (N, 3) of real numbers (converted to float64),\n"
      "faces (M, 3) of integer vertex indices. The mesh is validated: NaN/Inf vertices, indices out of range,\n"
      "no triangles or only zero-area ones raise clod.Error with the matching code; open, non-manifold or\n"
      "degenerate-containing meshes are accepted (see inspect()). Mesh.load(path) reads a file.");
  meshClass.def(py::init([](const ArrayLike& vertices, const ArrayLike& faces) { return meshFromArrays(vertices, faces); }), py::arg("vertices"),
           py::arg("faces"))
      .def_static("load", &loadPyMesh, py::arg("path"), py::arg("weld_tolerance_rel") = MeshLoadOptions{}.weldToleranceRel,
                  py::arg("orient_outward") = MeshLoadOptions{}.orientOutward,
                  "Loads a mesh file (OBJ, STL, PLY, OFF, glTF/GLB): triangulated, vertices closer than\n"
                  "weld_tolerance_rel x the bounding-box diagonal welded (negative: no welding), an inside-out closed\n"
                  "mesh flipped when orient_outward. Raises clod.FileError (missing, unreadable, empty) or clod.Error\n"
                  "(unknown_format, parse_error, non_finite_vertex, index_out_of_range, no_triangles, ...).\n"
                  "Non-fatal findings are in inspect()[\"warnings\"]. Releases the GIL.")
      .def_static(
          "box", [](const ArrayLike& half) {
            DoubleArray h = toDoubleArray(half, "half_extents");
            if (h.size() != 3) invalidArgument("half_extents: expected 3 numbers, got shape " + shapeText(h));
            TriangleMesh box = makeBox(Vec3(h.data()[0], h.data()[1], h.data()[2]));
            MeshReport report = requireValidMesh(box);
            return makePyMesh(std::move(box), std::move(report));
          },
          py::arg("half_extents"), "Axis-aligned box centred at the origin (12 triangles, 8 vertices).")
      .def_static(
          "icosphere", [](double radius, std::uint32_t subdivisions) {
            TriangleMesh sphere = makeIcosphere(radius, subdivisions);
            MeshReport report = requireValidMesh(sphere);
            return makePyMesh(std::move(sphere), std::move(report));
          },
          py::arg("radius"), py::arg("subdivisions") = 3,
          "Icosphere of the given radius centred at the origin (20 x 4^subdivisions triangles, vertices on the sphere).")
      .def_property_readonly(
          "vertices", [](py::object self) {
            const PyMesh& m = self.cast<const PyMesh&>();
            return readOnlyView(m.mesh->vertices.empty() ? nullptr : m.mesh->vertices.front().data(),
                                {py::ssize_t(m.mesh->vertexCount()), 3}, self);
          },
          "(N, 3) float64, read-only view")
      .def_property_readonly(
          "faces", [](py::object self) {
            const PyMesh& m = self.cast<const PyMesh&>();
            return readOnlyView(m.mesh->triangles.empty() ? nullptr : m.mesh->triangles.front().data(),
                                {py::ssize_t(m.mesh->triangleCount()), 3}, self);
          },
          "(M, 3) uint32 vertex indices, read-only view")
      .def_property_readonly("vertex_count", [](const PyMesh& m) { return m.mesh->vertexCount(); }, "N, the number of vertices")
      .def_property_readonly("triangle_count", [](const PyMesh& m) { return m.mesh->triangleCount(); }, "M, the number of triangles")
      .def_property_readonly(
          "bounds", [](const PyMesh& m) {
            const Aabb box = m.mesh->bounds();
            py::array_t<double> out({2, 3});
            for (int k = 0; k < 3; ++k) {
              out.mutable_data()[k] = box.min[k];
              out.mutable_data()[3 + k] = box.max[k];
            }
            return out;
          },
          "(2, 3) float64: bounding box, [min, max]")
      .def_property_readonly("diagonal", [](const PyMesh& m) { return m.mesh->bounds().diagonal(); },
                             "length of the bounding-box diagonal: the unit of clod's relative tolerances")
      .def_property_readonly(
          "edges", [](const PyMesh& m) {
            py::array_t<std::uint32_t> out;
            {
              py::gil_scoped_release release;
              (void)m.distance(false);
            }
            const auto edges = m.distance(false).topology().edges();
            out = py::array_t<std::uint32_t>({py::ssize_t(edges.size()), py::ssize_t(2)});
            for (std::size_t i = 0; i < edges.size(); ++i) {
              out.mutable_data()[2 * i] = edges[i].v0;
              out.mutable_data()[2 * i + 1] = edges[i].v1;
            }
            return out;
          },
          "(E, 2) uint32: the mesh's edge table (vertex pairs); ClosestResult.feature_index of an edge indexes it")
      .def_property_readonly(
          "sign_method", [](const PyMesh& m) {
            py::gil_scoped_release release;
            return std::string(signMethodName(m.distance(false).signMethod()));
          },
          "how closest() decides inside/outside by default: \"pseudonormal\" or \"winding_number\"")
      .def("inspect", &inspectMesh,
           "The validation report as a dict (the keys of `clod inspect --json`): counts, closed, consistently_oriented,\n"
           "boundary/non-manifold edges, components, bbox, surface_area, signed_volume (None unless closed and\n"
           "oriented), usable, issues [{fatal: code name or None, message}], and the loader's warnings.")
      .def("mass_properties", &massPropertiesDict, py::arg("density") = 1.0, py::arg("bounding_box_fallback") = false,
           "Mass properties of the solid the mesh bounds at uniform density: {volume, mass, center_of_mass (3,),\n"
           "inertia (3, 3) about the centre of mass}. Exact polyhedral integrals. An open mesh raises\n"
           "clod.Error(unsupported_mesh), unless bounding_box_fallback: then its bounding box's solid is used.")
      .def("closest", &closestPoints, py::arg("points"), py::arg("sign") = "auto",
           "Exact closest point, feature, normal, distance and signed distance (negative inside) for each row of\n"
           "points (K, 3). sign=\"auto\" uses pseudonormals on closed oriented manifold meshes and winding numbers\n"
           "otherwise; \"winding_number\" forces winding numbers. Runs in parallel (TBB) with the GIL released;\n"
           "the distance structure is built on the first call (O(T log T)) and reused.\n"
           "Raises clod.InvalidArgumentError for a wrong shape or dtype or a non-finite point.")
      .def(py::pickle(
          [](const PyMesh& m) {
            py::array_t<double> v({py::ssize_t(m.mesh->vertexCount()), py::ssize_t(3)});
            py::array_t<std::uint32_t> f({py::ssize_t(m.mesh->triangleCount()), py::ssize_t(3)});
            if (m.mesh->vertexCount()) std::memcpy(v.mutable_data(), m.mesh->vertices.data(), v.nbytes());
            if (m.mesh->triangleCount()) std::memcpy(f.mutable_data(), m.mesh->triangles.data(), f.nbytes());
            return py::make_tuple(v, f);
          },
          [](const py::tuple& state) {
            if (state.size() != 2) invalidArgument("Mesh.__setstate__: expected (vertices, faces)");
            return meshFromArrays(state[0], state[1]);
          }))
      .def("__repr__", [](const PyMesh& m) {
        return "<clod.Mesh " + std::to_string(m.mesh->vertexCount()) + " vertices, " + std::to_string(m.mesh->triangleCount()) +
               " triangles" + (m.report.closed ? ", closed" : ", open") + ">";
      });

  py::class_<PyBake, std::shared_ptr<PyBake>>(
      mod, "Bake",
      "Everything clod precomputes for one mesh (a .clod bake file): the mesh, its sphere-tree, and optionally\n"
      "closest feature maps (needed by the cfm and average models) and a contact tree (contact-tree model).\n"
      "Make one with clod.bake(mesh, ...) or Bake.load(path); immutable; picklable (as its file bytes).")
      .def_static(
          "load", [](const std::string& path) {
            py::gil_scoped_release release;
            return makePyBake(loadBake(path), std::nullopt);
          },
          py::arg("path"),
          "Reads a bake file; every byte is checked (clod.FileError; clod.Error bake_truncated, bake_corrupt,\n"
          "bake_version, bake_missing_section). Releases the GIL.")
      .def_static("from_bytes", &bakeFromBytes, py::arg("data"), "Decodes the bytes of a bake file (see to_bytes).")
      .def("to_bytes", &bakeToBytes, "The bake file's bytes (deterministic: equal contents give equal bytes).")
      .def(
          "save", [](const PyBake& b, const std::string& path) {
            py::gil_scoped_release release;
            return saveBake(path, *b.contents);
          },
          py::arg("path"), "Writes the bake file atomically (never a partial file); returns the bytes written.")
      .def_property_readonly(
          "mesh", [](const PyBake& b) { return makePyMesh(b.contents->mesh, validateMesh(b.contents->mesh)); },
          "the baked mesh (a new clod.Mesh each time)")
      .def_property_readonly("mesh_hash", [](const PyBake& b) { return b.contents->meshHash; }, "XXH3-64 content hash of the mesh")
      .def_property_readonly("source_name", [](const PyBake& b) { return b.contents->sourceName; }, "where the mesh came from (its file name), may be empty")
      .def_property_readonly("sphere_count", [](const PyBake& b) { return b.contents->sphereTree.sphereCount(); }, "spheres on all levels")
      .def_property_readonly("level_count", [](const PyBake& b) { return b.contents->sphereTree.levelCount(); },
                             "sphere-tree levels, root included")
      .def_property_readonly("has_closest_feature_map", [](const PyBake& b) { return b.contents->closestFeatureMap.has_value(); },
                             "True when the bake has closest feature maps (the cfm and average models need them)")
      .def_property_readonly("has_contact_tree", [](const PyBake& b) { return b.contents->contactTree.has_value(); },
                             "True when the bake has a contact tree (the contact-tree model needs it)")
      .def_property_readonly("diagonal", [](const PyBake& b) { return b.body->diagonal(); }, "bounding-box diagonal of the mesh")
      .def("spheres", &bakeSpheres, py::arg("level") = -1,
           "(centers (n, 3), radii (n,)) of one sphere-tree level (root = 0), or of every sphere (level=-1,\n"
           "breadth-first order).")
      .def("report", &bakeReport,
           "How clod.bake built it: {levels [{level, spheres, fit_mean, fit_max}] (fit in units of the diagonal),\n"
           "sign_method, *_seconds, sdf_cells, ...}; None for a bake read from a file.")
      .def(py::pickle([](const PyBake& b) { return bakeToBytes(b); }, [](const py::bytes& data) { return bakeFromBytes(data); }))
      .def("__repr__", [](const PyBake& b) {
        return "<clod.Bake '" + b.contents->sourceName + "' " + std::to_string(b.contents->mesh.triangleCount()) + " triangles, " +
               std::to_string(b.contents->sphereTree.sphereCount()) + " spheres" + (b.contents->closestFeatureMap ? ", cfm" : "") +
               (b.contents->contactTree ? ", contact tree" : "") + ">";
      });

  const BakeSettings defaults;
  mod.def("bake", &bakePyMesh, py::arg("mesh"), py::kw_only(),
        py::arg("sphere_tree") = std::string(sphereTreeMethodName(defaults.sphereTree.method)),
        py::arg("branching") = defaults.sphereTree.branching, py::arg("levels") = defaults.sphereTree.depth,
        py::arg("medial_samples") = defaults.sphereTree.medialSamples,
        py::arg("closest_feature_map") = defaults.buildClosestFeatureMap,
        py::arg("sampling") = std::string(samplingSchemeName(defaults.closestFeatureMap.scheme)),
        py::arg("stacks") = defaults.closestFeatureMap.rootStacks, py::arg("min_stacks") = defaults.closestFeatureMap.minStacks,
        py::arg("normal_codec") = std::string(normalCodecName(defaults.closestFeatureMap.codec)),
        py::arg("contact_tree") = defaults.buildContactTree, py::arg("sdf_error") = defaults.contactTree.errorRel,
        py::arg("sdf_depth") = defaults.contactTree.maxDepth, py::arg("measure_fit") = defaults.measureFit,
        py::arg("source_name") = std::string(),
        "Bakes a mesh: sphere-tree (sphere_tree \"octree\" or \"medial\", branching 2..64 children per sphere,\n"
        "levels 0..8 below the root, medial_samples for the medial builder), closest feature maps (sampling\n"
        "scheme, stacks at the root, min_stacks, normal_codec \"oct16\"/\"oct32\"; closest_feature_map=False\n"
        "skips them) and the contact tree (sdf_error relative to the bounding-box diagonal, sdf_depth 1..20;\n"
        "contact_tree=False skips it). The same options as `clod bake`. Out-of-range options raise\n"
        "clod.InvalidArgumentError naming the option. Multi-threaded (TBB), GIL released; deterministic.");
}

}  // namespace clod::python

PYBIND11_MODULE(_clod, m) {
  m.doc() =
      "clod's compiled core (import clod, not clod._clod): time-critical collision detection and contact\n"
      "generation between rigid triangle meshes. See docs/python.md.";
  clod::python::bindCore(m);
  clod::python::bindDynamics(m);
}
