#include "clod/bake.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>
#include <vector>

#define XXH_STATIC_LINKING_ONLY  // XXH3_state_t on the stack: no allocation, no failure path
#include <xxhash.h>

#include "clod/atomic_file.h"
#include "clod/bake_file.h"
#include "clod/error.h"
#include "cfm_section.h"
#include "contact_tree_section.h"
#include "mesh_section.h"
#include "sphere_tree_bounds_check.h"
#include "sphere_tree_section.h"

namespace clod {

std::uint64_t meshContentHash(const TriangleMesh& mesh) noexcept {
  XXH3_state_t state;
  XXH3_INITSTATE(&state);
  XXH3_64bits_reset(&state);
  const std::uint64_t counts[2] = {mesh.vertices.size(), mesh.triangles.size()};
  XXH3_64bits_update(&state, counts, sizeof(counts));
  // Vec3 and Triangle are packed (mesh_section.cpp asserts it), so the arrays are already the
  // little-endian f64 / u32 sequences the hash is defined on.
  XXH3_64bits_update(&state, mesh.vertices.data(), mesh.vertices.size() * sizeof(Vec3));
  XXH3_64bits_update(&state, mesh.triangles.data(), mesh.triangles.size() * sizeof(Triangle));
  return XXH3_64bits_digest(&state);
}

std::vector<std::byte> encodeBake(const BakeContents& contents) {
  // Refuse to write what decodeBake would refuse to read.
  detail::checkMesh(contents.mesh, {ErrorCode::kInvalidArgument, "encodeBake: mesh"});
  detail::checkSphereTree(contents.sphereTree, contents.sphereTreeSettings, contents.mesh.triangleCount(),
                          {ErrorCode::kInvalidArgument, "encodeBake: sphere-tree"});
  detail::checkSphereTreeBoundsMesh(contents.sphereTree, contents.mesh,
                                    {ErrorCode::kInvalidArgument, "encodeBake: sphere-tree"});
  BakeFileWriter writer;
  writer.addSection(kBakeMeshTag, kBakeMeshVersion,
                    detail::encodeMeshSection(contents.mesh, meshContentHash(contents.mesh), contents.sourceName));
  writer.addSection(kBakeSphereTreeTag, kBakeSphereTreeVersion,
                    detail::encodeSphereTreeSection(contents.sphereTree, contents.sphereTreeSettings));
  if (contents.closestFeatureMap) {
    try {  // the map must belong to this tree: re-check it as the decoder will
      ClosestFeatureMap::fromData(contents.closestFeatureMap->data(), contents.sphereTree);
    } catch (const Error& e) {
      throw Error(ErrorCode::kInvalidArgument, std::string("encodeBake: ") + e.what());
    }
    writer.addSection(kBakeCfmTag, kBakeCfmVersion, detail::encodeCfmSection(*contents.closestFeatureMap));
  }
  if (contents.contactTree) {
    detail::checkContactTree(*contents.contactTree, contents.mesh, {ErrorCode::kInvalidArgument, "encodeBake"});
    writer.addSection(kBakeContactTreeTag, kBakeContactTreeVersion, detail::encodeContactTreeSection(*contents.contactTree));
  }
  return writer.encode();
}

BakeContents decodeBake(std::span<const std::byte> bytes) {
  const BakeFileReader file(bytes);
  BakeContents contents;
  {
    detail::DecodedMeshSection mesh = detail::decodeMeshSection(file.section(kBakeMeshTag, kBakeMeshVersion).payload);
    contents.mesh = std::move(mesh.mesh);
    contents.meshHash = mesh.hash;
    contents.sourceName = std::move(mesh.sourceName);
  }
  {
    const BakeSection section = file.section(kBakeSphereTreeTag, kBakeSphereTreeVersion);
    detail::DecodedSphereTreeSection tree =
        detail::decodeSphereTreeSection(section.payload, contents.mesh.triangleCount(), section.version);
    detail::checkSphereTreeBoundsMesh(tree.tree, contents.mesh, {ErrorCode::kBakeCorrupt, "bake section 'STRE'"});
    contents.sphereTree = std::move(tree.tree);
    contents.sphereTreeSettings = tree.settings;
  }
  if (const std::optional<BakeSection> cfm = file.findSection(kBakeCfmTag, kBakeCfmVersion)) {
    contents.closestFeatureMap = detail::decodeCfmSection(cfm->payload, contents.sphereTree, cfm->version);
  }
  if (const std::optional<BakeSection> tree = file.findSection(kBakeContactTreeTag, kBakeContactTreeVersion)) {
    contents.contactTree = detail::decodeContactTreeSection(tree->payload, contents.mesh);
  }
  return contents;
}

std::size_t saveBake(const std::filesystem::path& path, const BakeContents& contents) {
  const std::vector<std::byte> bytes = encodeBake(contents);
  writeFileAtomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  return bytes.size();
}

namespace {

// Closes a descriptor on every exit path.
struct FileDescriptor {
  int fd = -1;
  ~FileDescriptor() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

BakeContents loadBake(const std::filesystem::path& path) {
  std::string name = path.string();  // built in place: GCC 12 warns falsely (-Wrestrict) on "'" + string
  name.insert(name.begin(), '\'');
  name.push_back('\'');
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw Error(ErrorCode::kFileNotFound, name + " does not exist");
  if (std::filesystem::is_directory(status)) throw Error(ErrorCode::kFileUnreadable, name + " is a directory");

  // One open, one fstat, the header (and section table) checked before the rest is read or
  // even allocated -- a large file that is not a bake costs 48 bytes of reading -- then (almost
  // always) one read into a buffer that is not zeroed first: loading is bounded by the
  // checksums and the copies into the decoded arrays, not by I/O calls.
  FileDescriptor file{::open(path.c_str(), O_RDONLY | O_CLOEXEC)};
  if (file.fd < 0) throw Error(ErrorCode::kFileUnreadable, name + ": cannot open: " + std::strerror(errno));
  struct stat info {};
  if (::fstat(file.fd, &info) != 0) throw Error(ErrorCode::kFileUnreadable, name + ": cannot stat: " + std::strerror(errno));
  if (!S_ISREG(info.st_mode)) throw Error(ErrorCode::kFileUnreadable, name + " is not a regular file");
  auto size = static_cast<std::size_t>(info.st_size);
  if (size == 0) throw Error(ErrorCode::kEmptyFile, name + " is empty");
  std::size_t done = 0;
  // Reads until `want` bytes are in `into` or the file ends (it shrank since fstat: then the
  // checks see the shorter size and say truncated).
  auto readUpTo = [&](std::byte* into, std::size_t want) {
    while (done < want) {
      const ssize_t got = ::read(file.fd, into + done, want - done);
      if (got < 0 && errno == EINTR) continue;
      if (got < 0) throw Error(ErrorCode::kFileUnreadable, name + ": I/O error: " + std::strerror(errno));
      if (got == 0) {
        size = done;
        break;
      }
      done += static_cast<std::size_t>(got);
    }
  };
  std::vector<std::byte> start;
  try {
    for (std::size_t need = std::min<std::size_t>(size, kBakeHeaderSize); need != 0;
         need = checkBakeFileStart({start.data(), done}, size)) {
      start.resize(need);
      readUpTo(start.data(), need);
    }
  } catch (const Error& e) {
    throw Error(e.code(), name + ": " + e.what());
  }
  auto buffer = std::make_unique_for_overwrite<std::byte[]>(size);
  std::memcpy(buffer.get(), start.data(), done);
  readUpTo(buffer.get(), size);
  try {
    return decodeBake({buffer.get(), done});
  } catch (const Error& e) {
    throw Error(e.code(), name + ": " + e.what());
  }
}

}  // namespace clod
