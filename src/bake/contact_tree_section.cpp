#include "contact_tree_section.h"

#include <cstring>
#include <string>

#include "clod/byte_stream.h"
#include "clod/contact_tree_codec.h"
#include "clod/error.h"

namespace clod::detail {

namespace {

// The codec validates the tree on its own; what it cannot know is which mesh the tree belongs
// to. The builder sets meshDiagonal = mesh.bounds().diagonal() and a root cube enclosing the
// box (contact_tree_builder.h), so a tree from another mesh (or a damaged field that still
// passes the codec) shows up here.
void checkTreeBelongsToMesh(const ContactTree& tree, const TriangleMesh& mesh, const Complaint& complain) {
  const Aabb box = mesh.bounds();
  const double diagonal = box.diagonal();
  if (std::memcmp(&tree.meshDiagonal, &diagonal, sizeof(double)) != 0) {
    complain("contact tree: meshDiagonal " + std::to_string(tree.meshDiagonal) +
             " differs from the mesh's bounding-box diagonal " + std::to_string(diagonal) +
             " (the tree was built for another mesh)");
  }
  if (box.empty()) return;
  const Vec3 upper = tree.origin + Vec3::Constant(tree.rootSize);
  for (int axis = 0; axis < 3; ++axis) {
    if (!(tree.origin[axis] <= box.min[axis] && box.max[axis] <= upper[axis])) {
      complain("contact tree: root cube does not contain the mesh's bounding box along axis " + std::to_string(axis));
    }
  }
}

}  // namespace

void checkContactTree(const ContactTree& tree, const TriangleMesh& mesh, const Complaint& complain) {
  // The codec's decoder holds the complete list of invariants; running it on the encoding keeps
  // encoder and decoder from ever disagreeing about what a valid tree is.
  ByteWriter writer;
  encodeContactTree(tree, writer);
  ByteReader reader(writer.bytes().data(), writer.size(), complain.context);
  try {
    (void)decodeContactTree(reader);
  } catch (const Error& e) {
    throw Error(complain.code, e.what());
  }
  checkTreeBelongsToMesh(tree, mesh, complain);
}

std::vector<std::byte> encodeContactTreeSection(const ContactTree& tree) {
  ByteWriter writer;
  encodeContactTree(tree, writer);
  return writer.take();
}

ContactTree decodeContactTreeSection(std::span<const std::byte> payload, const TriangleMesh& mesh) {
  ByteReader reader(payload.data(), payload.size(), "bake section 'CTRE'");
  ContactTree tree = decodeContactTree(reader);
  if (!reader.atEnd()) reader.fail(std::to_string(reader.remaining()) + " unexpected bytes after the contact tree");
  checkTreeBelongsToMesh(tree, mesh, {ErrorCode::kBakeCorrupt, "bake section 'CTRE'"});
  return tree;
}

}  // namespace clod::detail
