#include "clod/mesh_io.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <utility>

#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>
#include <assimp/commonMetaData.h>
#include <assimp/config.h>
#include <assimp/scene.h>

#include "clod/error.h"
#include "clod/atomic_file.h"
#include "clod/mesh_weld.h"
#include "load_limits.h"
#include "off_reader.h"
#include "polygon_triangulation.h"
#include "text_index_check.h"

namespace clod {

namespace {

// No Assimp post-processing at all. Triangulate: its ear clipping takes ~n^2.3 for a face of
// n corners (> 400 s for one 100,000-corner OBJ face), and the packaged Assimp, built with its
// asserts on, aborts on a face without indices; polygons are triangulated in convertScene
// instead (polygon_triangulation.h). JoinIdenticalVertices: we weld with a tolerance.
// FindDegenerates / FindInvalidData: they drop or alter triangles, hiding the counts we report.
// FixInfacingNormals: it guesses; we orient by signed volume. ValidateDataStructure: we check
// ourselves (checkRawScene). PreTransformVertices: we apply node transforms ourselves,
// instancing meshes referenced by several nodes.
constexpr unsigned kImportFlags = 0;

// Some Assimp importers repair bad data and only log it (the OFF reader clamps an out-of-range
// index to the last vertex; the glTF reader drops faces with out-of-range indices). So every
// import runs with a capturing log stream: those messages become errors or warnings instead of
// silent changes. Assimp's logger is a process-wide singleton, hence the mutex: imports are
// serialised (loading is not a hot path). Nothing is ever printed: without a logger of the
// application's own, ours has no stream but the capturing one and is destroyed afterwards.
class CapturedLog final : public Assimp::LogStream {
public:
  void write(const char* message) override {
    std::string line = message ? message : "";
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    // DefaultLogger prefixes "Error, T0: " / "Warn,  T0: "; keep the text after it.
    const bool isError = line.starts_with("Error");
    if (auto colon = line.find(": "); colon != std::string::npos && line.starts_with(isError ? "Error" : "Warn"))
      line = line.substr(colon + 2);
    if (messages_.size() < 64) messages_.push_back(line);
  }
  const std::vector<std::string>& messages() const { return messages_; }

private:
  std::vector<std::string> messages_;
};

std::mutex& importMutex() {
  static std::mutex mutex;
  return mutex;
}

// Runs `import` (which calls the importer) with a capturing logger attached.
template <class ImportFn>
const aiScene* importCapturingLog(Assimp::Importer& importer, CapturedLog& log, ImportFn&& import) {
  std::lock_guard lock(importMutex());
  const bool ownLogger = Assimp::DefaultLogger::isNullLogger();
  if (ownLogger) Assimp::DefaultLogger::create("", Assimp::Logger::NORMAL, 0);
  Assimp::Logger* logger = Assimp::DefaultLogger::get();
  logger->attachStream(&log, Assimp::Logger::Err | Assimp::Logger::Warn);
  const aiScene* scene = nullptr;
  try {
    scene = import(importer);
  } catch (...) {
    // Assimp catches its own exceptions; this is only for std::bad_alloc and the like.
    logger->detachStream(&log, Assimp::Logger::Err | Assimp::Logger::Warn);
    if (ownLogger) Assimp::DefaultLogger::kill();
    throw;
  }
  logger->detachStream(&log, Assimp::Logger::Err | Assimp::Logger::Warn);  // ownership returns to us
  if (ownLogger) Assimp::DefaultLogger::kill();
  return scene;
}

// What Assimp's post-processing assumes of a scene, checked before it runs: vertex and face
// arrays present, every face with at least one index, every index in range.
void checkRawScene(const aiScene* scene, const std::string& source) {
  if (scene->mNumMeshes > 0 && !scene->mMeshes) throw Error(ErrorCode::kParseError, source + ": mesh list missing");
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    const std::string where = source + ": mesh " + std::to_string(m);
    if (!mesh) throw Error(ErrorCode::kParseError, where + " missing");
    if (mesh->mNumVertices > 0 && !mesh->mVertices) throw Error(ErrorCode::kParseError, where + ": no vertex positions");
    if (mesh->mNumFaces > 0 && !mesh->mFaces) throw Error(ErrorCode::kParseError, where + ": no faces");
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices == 0 || !face.mIndices)
        throw Error(ErrorCode::kParseError, where + ", face " + std::to_string(f) + ": no vertex indices");
      for (unsigned k = 0; k < face.mNumIndices; ++k)
        if (face.mIndices[k] >= mesh->mNumVertices)
          throw Error(ErrorCode::kIndexOutOfRange, where + ", face " + std::to_string(f) + ": vertex index " +
                                                       std::to_string(face.mIndices[k]) + " >= vertex count " +
                                                       std::to_string(mesh->mNumVertices));
    }
  }
}

// The importer's scene, checked (see kImportFlags).
const aiScene* importChecked(const aiScene* raw, const std::string& source) {
  if (raw) checkRawScene(raw, source);
  return raw;
}

// Coordinates as written in the file (docs/conventions.md). Assimp's Collada reader rotates
// Z-up and X-up files to Y-up unless told not to; its <unit> scaling is undone in convertScene.
void configureImporter(Assimp::Importer& importer) {
  importer.SetPropertyInteger(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, 1);
}

bool mentionsIndexOutOfRange(const std::string& message) {
  return message.find("out of range") != std::string::npos || message.find("out-of-range") != std::string::npos;
}

// Assimp reports every failure as a string; "No suitable reader" is the only way to tell an
// unknown format from a malformed file of a known format.
[[noreturn]] void throwImportError(const std::string& source, const char* assimpMessage, std::string_view format,
                                   std::string_view text) {
  const std::string message = assimpMessage ? assimpMessage : "";
  if (message.find("No suitable reader") != std::string::npos)
    throw Error(ErrorCode::kUnknownFormat, source + ": unknown file format (" + message + ")");
  if (mentionsIndexOutOfRange(message)) {
    std::optional<std::string> where;
    if (format == "obj") where = detail::findBadObjIndex(text);
    throw Error(ErrorCode::kIndexOutOfRange, source + ": " + (where ? *where : message));
  }
  throw Error(ErrorCode::kParseError, source + ": " + (message.empty() ? std::string("import failed") : message));
}

// Turns what the importer logged into errors (index repairs) or warnings (everything else).
void applyLog(const CapturedLog& log, const std::string& source, std::vector<std::string>& warnings) {
  for (const std::string& message : log.messages()) {
    if (mentionsIndexOutOfRange(message))
      throw Error(ErrorCode::kIndexOutOfRange, source + ": " + message + " (the importer would have repaired it silently)");
    warnings.push_back("importer: " + message);
  }
}

std::string lowercase(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

struct Instance {
  const aiNode* node;
  aiMatrix4x4 transform;
};

// Vertex and triangle totals of the mesh convertScene would build (each mesh once per node that
// refers to it) and the largest polygon, held against the limits before anything is copied.
void checkSceneAgainstLimits(const aiScene* scene, const std::string& source, const MeshLoadOptions& options) {
  std::vector<std::uint64_t> trianglesOfMesh(scene->mNumMeshes, 0);
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const unsigned corners = mesh->mFaces[f].mNumIndices;
      if (corners > options.maxPolygonVertices)
        detail::enforceLimit(corners, options.maxPolygonVertices, "maxPolygonVertices", "corners in one face",
                             source + ": mesh " + std::to_string(m) + ", face " + std::to_string(f));
      if (corners >= 3) trianglesOfMesh[m] += corners - 2;
    }
  }
  std::uint64_t vertices = 0, triangles = 0;
  std::vector<const aiNode*> stack;
  if (scene->mRootNode) stack.push_back(scene->mRootNode);
  while (!stack.empty()) {
    const aiNode* node = stack.back();
    stack.pop_back();
    for (unsigned c = 0; c < node->mNumChildren; ++c)
      if (node->mChildren[c]) stack.push_back(node->mChildren[c]);
    for (unsigned k = 0; k < node->mNumMeshes; ++k) {
      const unsigned m = node->mMeshes[k];
      if (m >= scene->mNumMeshes) continue;  // convertScene names it
      vertices += scene->mMeshes[m]->mNumVertices;
      triangles += trianglesOfMesh[m];
    }
    detail::enforceLimit(vertices, options.maxVertices, "maxVertices", "vertices or more in the imported scene", source);
    detail::enforceLimit(triangles, options.maxTriangles, "maxTriangles", "triangles or more in the imported scene", source);
  }
}

void noteFannedPolygons(std::uint64_t count, std::vector<std::string>& warnings) {
  if (count > 0)
    warnings.push_back(std::to_string(count) + " polygon(s) not simple in their best-fit plane (self-intersecting, "
                       "zero area or strongly warped) were fan-triangulated from their first corner");
}

// Everything after reading, shared by all formats: fatal checks, weld, validate, orient.
LoadedMesh finishMesh(LoadedMesh result, std::uint64_t ignoredPrimitives, const std::string& source,
                      const MeshLoadOptions& options) {
  TriangleMesh& mesh = result.mesh;
  // Readers may leave non-finite coordinates in (the Assimp path checks earlier, with the mesh
  // and node in the message); welding needs finite ones.
  for (std::uint32_t v = 0; v < mesh.vertexCount(); ++v) {
    const Vec3& p = mesh.vertices[v];
    if (!p.allFinite())
      throw Error(ErrorCode::kNonFiniteVertex, source + ": vertex " + std::to_string(v) + ": non-finite coordinate (" +
                                                   std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " +
                                                   std::to_string(p.z()) + ")");
  }
  result.importedVertexCount = mesh.vertexCount();
  if (mesh.triangles.empty())
    throw Error(ErrorCode::kNoTriangles, source + ": no triangles (" + std::to_string(mesh.vertexCount()) + " vertices, " +
                                             std::to_string(ignoredPrimitives) + " points/lines)");

  const double diagonal = mesh.bounds().diagonal();
  // Relative tolerances square and cube the diagonal; past ~1e100 that overflows.
  if (!(diagonal < 1e100))
    throw Error(ErrorCode::kUnsupportedMesh, source + ": bounding-box diagonal " + std::to_string(diagonal) + " is too large");
  if (options.weldToleranceRel >= 0.0) {
    result.weldToleranceAbs = options.weldToleranceRel * diagonal;
    if (!std::isfinite(result.weldToleranceAbs))
      throw Error(ErrorCode::kInvalidArgument, "weldToleranceRel " + std::to_string(options.weldToleranceRel) + " is too large");
    const WeldResult weld = weldVertices(mesh, result.weldToleranceAbs);
    result.weldedVertexCount = weld.mergedCount;
  }

  result.report = validateMesh(mesh);
  try {
    throwIfUnusable(result.report);
  } catch (const Error& e) {
    throw Error(e.code(), source + ": " + e.what());
  }
  if (options.orientOutward && result.report.insideOut()) {
    flipOrientation(mesh);
    result.flipped = true;
    result.report = validateMesh(mesh);
  }
  result.warnings.reserve(result.warnings.size() + result.report.issues.size() + 2);
  for (const MeshIssue& issue : result.report.issues) result.warnings.push_back(issue.message);
  if (result.flipped) result.warnings.push_back("the mesh was inside-out: every triangle was flipped");
  if (ignoredPrimitives > 0)
    result.warnings.push_back(std::to_string(ignoredPrimitives) + " points/lines in the file were ignored");
  return result;
}

// Whether Assimp's Collada reader made the scene (whatever the extension: Assimp also picks
// readers by content). Every reader of the packaged Assimp names itself in the metadata.
bool readByCollada(const aiScene* scene) {
  aiString reader;
  return scene->mMetaData && scene->mMetaData->Get(AI_METADATA_SOURCE_FORMAT, reader) &&
         std::string_view(reader.C_Str()).starts_with("Collada");
}

// The importer's scene as one mesh: every mesh of every node, node transforms applied,
// polygons triangulated, then finishMesh.
LoadedMesh convertScene(const aiScene* scene, const CapturedLog& log, const std::string& source,
                        const MeshLoadOptions& options) {
  LoadedMesh result;
  applyLog(log, source, result.warnings);
  checkSceneAgainstLimits(scene, source, options);
  TriangleMesh& mesh = result.mesh;
  std::uint64_t ignoredPrimitives = 0, fannedPolygons = 0;
  std::uint64_t totalVertices = 0;
  std::vector<std::uint32_t> corners;
  constexpr std::uint64_t kMaxElements = std::numeric_limits<std::uint32_t>::max() - 1;

  // Depth-first over the node graph with accumulated transforms; explicit stack, since a
  // hostile file can nest nodes deeply.
  std::vector<Instance> stack;
  // A Collada root node is the visual scene, which has no transform in the format: Assimp puts
  // the file's <unit> scale there (meter="0.01" would shrink the mesh 100 times), which we drop
  // to keep the coordinates as written. Its up-axis rotation is off (configureImporter).
  if (scene->mRootNode) stack.push_back({scene->mRootNode, readByCollada(scene) ? aiMatrix4x4() : scene->mRootNode->mTransformation});
  while (!stack.empty()) {
    const Instance instance = stack.back();
    stack.pop_back();
    const aiNode* node = instance.node;
    for (unsigned c = 0; c < node->mNumChildren; ++c)
      if (node->mChildren[c]) stack.push_back({node->mChildren[c], instance.transform * node->mChildren[c]->mTransformation});

    const aiMatrix4x4& m = instance.transform;
    // A mirroring transform reverses the winding; undo that so outward stays outward.
    const double det3 = double(m.a1) * (double(m.b2) * m.c3 - double(m.b3) * m.c2) -
                        double(m.a2) * (double(m.b1) * m.c3 - double(m.b3) * m.c1) +
                        double(m.a3) * (double(m.b1) * m.c2 - double(m.b2) * m.c1);
    const bool mirrored = det3 < 0.0;
    const std::string nodeName = node->mName.length ? std::string(node->mName.C_Str()) : std::string("(unnamed)");

    for (unsigned k = 0; k < node->mNumMeshes; ++k) {
      const unsigned meshIndex = node->mMeshes[k];
      if (meshIndex >= scene->mNumMeshes || !scene->mMeshes[meshIndex])
        throw Error(ErrorCode::kParseError, source + ": node '" + nodeName + "' refers to mesh " +
                                                std::to_string(meshIndex) + " of " + std::to_string(scene->mNumMeshes));
      const aiMesh* in = scene->mMeshes[meshIndex];
      const std::string where = source + ": mesh " + std::to_string(meshIndex) + " (node '" + nodeName + "')";
      totalVertices += in->mNumVertices;
      if (totalVertices > kMaxElements)
        throw Error(ErrorCode::kUnsupportedMesh, source + ": more than 2^32 - 2 vertices");
      if (in->mNumVertices > 0 && !in->mVertices) throw Error(ErrorCode::kParseError, where + ": no vertex positions");
      const std::uint32_t base = mesh.vertexCount();
      for (unsigned v = 0; v < in->mNumVertices; ++v) {
        const aiVector3D& p = in->mVertices[v];
        const Vec3 local(p.x, p.y, p.z);
        if (!local.allFinite())
          throw Error(ErrorCode::kNonFiniteVertex, where + ", vertex " + std::to_string(v) + ": non-finite coordinate (" +
                                                       std::to_string(local.x()) + ", " + std::to_string(local.y()) +
                                                       ", " + std::to_string(local.z()) + ")");
        const Vec3 world(m.a1 * local.x() + m.a2 * local.y() + m.a3 * local.z() + m.a4,
                         m.b1 * local.x() + m.b2 * local.y() + m.b3 * local.z() + m.b4,
                         m.c1 * local.x() + m.c2 * local.y() + m.c3 * local.z() + m.c4);
        if (!world.allFinite())
          throw Error(ErrorCode::kNonFiniteVertex, where + ", vertex " + std::to_string(v) +
                                                       ": coordinate not finite after the node transform");
        mesh.vertices.push_back(world);
      }
      if (in->mNumFaces > 0 && !in->mFaces) throw Error(ErrorCode::kParseError, where + ": no faces");
      for (unsigned f = 0; f < in->mNumFaces; ++f) {
        const aiFace& face = in->mFaces[f];
        if (face.mNumIndices < 3) {
          ++ignoredPrimitives;  // points and lines
          continue;
        }
        corners.clear();
        for (unsigned c = 0; c < face.mNumIndices; ++c) {
          const unsigned index = face.mIndices[c];
          if (index >= in->mNumVertices)
            throw Error(ErrorCode::kIndexOutOfRange, where + ", face " + std::to_string(f) + ": vertex index " +
                                                         std::to_string(index) + " >= vertex count " +
                                                         std::to_string(in->mNumVertices));
          corners.push_back(base + index);
        }
        const std::size_t first = mesh.triangles.size();
        // Triangulated in world coordinates: wound like the face there, then unmirrored below.
        if (detail::appendFaceTriangles(mesh.vertices, corners, mesh.triangles) == detail::PolygonCut::kFanFallback)
          ++fannedPolygons;
        if (mirrored)
          for (std::size_t t = first; t < mesh.triangles.size(); ++t) std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
        if (mesh.triangles.size() > kMaxElements) throw Error(ErrorCode::kUnsupportedMesh, source + ": more than 2^32 - 2 triangles");
      }
    }
  }

  noteFannedPolygons(fannedPolygons, result.warnings);
  return finishMesh(std::move(result), ignoredPrimitives, source, options);
}

// The checks Assimp needs before it sees the bytes (see text_index_check.h), and the declared
// counts against the limits (load_limits.h).
void checkText(std::string_view text, std::string_view format, const std::string& source,
               const MeshLoadOptions& options) {
  if (auto problem = detail::findPlyHeaderProblem(text)) throw Error(ErrorCode::kParseError, source + ": " + *problem);
  if (auto problem = detail::findGlbHeaderProblem(text)) throw Error(ErrorCode::kParseError, source + ": " + *problem);
  // glTF JSON, plain or in a GLB, is parsed by a recursive parser (MeshLoadOptions::maxJsonDepth).
  std::optional<std::string_view> json;
  if (detail::looksLikeGlb(text)) json = detail::glbJsonChunk(text);
  else if (detail::looksLikeJson(text)) json = text;
  if (json) {
    if (auto problem = detail::findJsonDepthProblem(*json, options.maxJsonDepth))
      throw Error(ErrorCode::kParseError, source + ": " + *problem);
  }
  if (auto problem = detail::findColladaNumberListProblem(text)) throw Error(ErrorCode::kParseError, source + ": " + *problem);
  detail::checkDeclaredCounts(text, format, source, options);
}

// OFF goes to our own reader (off_reader.h): by name, or by content whatever the name, because
// when the reader the name picks rejects the bytes, Assimp sniffs "off" in the first bytes and
// hands them to its OFF reader anyway (fuzz_mesh_load: OFF bytes with hint "glb" crashed it).
// No other supported format can start with "off".
bool useOffReader(std::string_view format, std::string_view head) {
  return format == "off" || detail::looksLikeOff(head);
}

LoadedMesh loadOff(std::string_view text, const std::string& source, const MeshLoadOptions& options) {
  detail::OffContent content = detail::readOff(text, source, options);
  LoadedMesh result;
  result.mesh = std::move(content.mesh);
  noteFannedPolygons(content.fannedPolygons, result.warnings);
  return finishMesh(std::move(result), content.ignoredPrimitives, source, options);
}

void checkOptions(const MeshLoadOptions& options) {
  if (std::isnan(options.weldToleranceRel)) throw Error(ErrorCode::kInvalidArgument, "weldToleranceRel is NaN");
}

}  // namespace

LoadedMesh loadMesh(const std::filesystem::path& path, const MeshLoadOptions& options) {
  checkOptions(options);
  const std::string source = std::string("'").append(path.string()).append("'");
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw Error(ErrorCode::kFileNotFound, source + " does not exist");
  if (std::filesystem::is_directory(status)) throw Error(ErrorCode::kFileUnreadable, source + " is a directory");
  if (!std::filesystem::is_regular_file(status)) throw Error(ErrorCode::kFileUnreadable, source + " is not a regular file");
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw Error(ErrorCode::kFileUnreadable, source + ": " + ec.message());
  if (size == 0) throw Error(ErrorCode::kEmptyFile, source + " is empty (0 bytes)");
  {
    // Assimp's own "cannot open" message does not tell permissions from format trouble.
    std::FILE* probe = std::fopen(path.c_str(), "rb");
    if (!probe) throw Error(ErrorCode::kFileUnreadable, "cannot open " + source + " for reading");
    std::fclose(probe);
  }
  std::string format = lowercase(path.extension().string());
  if (!format.empty()) format.erase(0, 1);
  // The bytes of OBJ, OFF, PLY, glTF, GLB and Collada files are needed (text_index_check.h,
  // off_reader.h).
  // Assimp sniffs content whatever the extension, so every file's first bytes are looked at.
  std::string text;
  if (format == "obj" || format == "off" || format == "ply" || format == "glb" || format == "gltf" || format == "dae") {
    text = readWholeFile(path);
  } else {
    char head[64] = {};
    if (std::FILE* file = std::fopen(path.c_str(), "rb")) {
      const std::size_t n = std::fread(head, 1, sizeof head, file);
      std::fclose(file);
      const std::string_view headText(head, n);
      // All whitespace: it may still be JSON further on (glTF is recognised by content too).
      const bool blank = headText.find_first_not_of(" \t\r\n") == std::string_view::npos;
      // XML may be Collada, which Assimp recognises by content too.
      const bool xml = headText.find("<?xml") != std::string_view::npos || detail::looksLikeCollada(headText);
      if (detail::looksLikePly(headText) || detail::looksLikeGlb(headText) || detail::looksLikeJson(headText) ||
          blank || xml || useOffReader(format, headText))
        text = readWholeFile(path);
    }
  }
  if (useOffReader(format, text)) return loadOff(text, source, options);
  checkText(text, format, source, options);

  Assimp::Importer importer;
  configureImporter(importer);
  CapturedLog log;
  // Through ReadFile, not from memory, so that a .gltf finds its external .bin next to it.
  const aiScene* scene = importCapturingLog(importer, log, [&](Assimp::Importer& imp) {
    return importChecked(imp.ReadFile(path.string(), kImportFlags), source);
  });
  if (!scene) throwImportError(source, importer.GetErrorString(), format, text);
  return convertScene(scene, log, source, options);
}

LoadedMesh loadMeshFromMemory(std::span<const std::byte> bytes, std::string_view formatHint,
                              const MeshLoadOptions& options) {
  checkOptions(options);
  if (formatHint.empty() || formatHint.size() > 15)
    throw Error(ErrorCode::kInvalidArgument, "format hint '" + std::string(formatHint) + "' must be 1 to 15 characters");
  for (char c : formatHint)
    if (!std::isalnum(static_cast<unsigned char>(c)))
      throw Error(ErrorCode::kInvalidArgument, "format hint '" + std::string(formatHint) + "' must be letters and digits");
  const std::string format = lowercase(std::string(formatHint));
  const std::string source = "<memory:" + format + ">";
  if (bytes.empty()) throw Error(ErrorCode::kEmptyFile, source + " is empty (0 bytes)");
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  if (useOffReader(format, text)) return loadOff(text, source, options);
  checkText(text, format, source, options);

  Assimp::Importer importer;
  configureImporter(importer);
  CapturedLog log;
  const aiScene* scene = importCapturingLog(importer, log, [&](Assimp::Importer& imp) {
    return importChecked(imp.ReadFileFromMemory(bytes.data(), bytes.size(), kImportFlags, format.c_str()), source);
  });
  if (!scene) throwImportError(source, importer.GetErrorString(), format, text);
  return convertScene(scene, log, source, options);
}

}  // namespace clod
