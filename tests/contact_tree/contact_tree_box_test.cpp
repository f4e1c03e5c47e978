// Analytic tests on a box, whose exact signed distance has a closed form (independent of
// clod::MeshDistance), plus the codec round trip and corruption tests.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "clod/contact_tree.h"
#include "clod/contact_tree_builder.h"
#include "clod/contact_tree_codec.h"
#include "clod/error.h"
#include "clod/primitives.h"
#include "clod/proximity.h"
#include "tree_cache.h"

namespace clod {
namespace {

// Signed distance to the axis-aligned box [-half, half] (Quilez's closed form).
double boxDistance(const Vec3& p, const Vec3& half) {
  const Vec3 q = p.cwiseAbs() - half;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

struct BoxTree {
  Vec3 half{1.0, 0.6, 0.35};
  MeshDistance exact{makeBox(half)};
  ContactTree tree;
  ContactTreeBuildStats stats;
  BoxTree() {
    ContactTreeSettings settings;
    settings.errorRel = 2e-3;
    tree = buildContactTree(exact, settings, &stats);
  }
};

const BoxTree& boxTree() {
  static const BoxTree box;
  return box;
}

TEST(ContactTreeBox, DistanceMatchesTheClosedFormInTheBand) {
  const BoxTree& box = boxTree();
  const double diag = 2.0 * box.half.norm();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  int inBand = 0;
  for (int i = 0; i < 40000; ++i) {
    const Vec3 p = Vec3(uni(rng), uni(rng), uni(rng)).cwiseProduct(box.half + Vec3::Constant(0.02 * diag));
    const double exact = boxDistance(p, box.half);
    if (std::abs(exact) > box.tree.bandAbs) continue;
    ++inBand;
    // eps_s plus float rounding of the stored corners (2^-23 of the diagonal, see the accuracy test).
    ASSERT_NEAR(box.tree.distance(p), exact, box.tree.errorAbs + std::ldexp(diag, -23)) << p.transpose();
  }
  EXPECT_GT(inBand, 1000);
}

TEST(ContactTreeBox, GradientOnAFaceIsTheFaceNormal) {
  // Away from edges (farther than the band) the box's distance field is linear, so the trilinear
  // gradient must be the face normal up to float rounding of the corner values.
  const BoxTree& box = boxTree();
  const Vec3 onTop(0.3, -0.2, box.half.z());
  for (double offset : {-0.01, 0.0, 0.01}) {
    const ContactFieldSample s = box.tree.sample(onTop + Vec3(0, 0, offset));
    const Vec3 n = s.gradient.normalized();
    EXPECT_GT(n.z(), std::cos(1e-4)) << n.transpose();
    EXPECT_NEAR(s.distance, offset, 1e-6);
  }
}

TEST(ContactTreeBox, FaceCellHalfSpacesAreTheFacePlanes) {
  const BoxTree& box = boxTree();
  const ContactTree& tree = box.tree;
  int checked = 0;
  std::vector<ContactCell> stack{tree.rootCell()};
  while (!stack.empty()) {
    const ContactCell cell = stack.back();
    stack.pop_back();
    if (!tree.isLeaf(cell.node)) {
      for (std::uint32_t o = 0; o < 8; ++o) stack.push_back(tree.childCell(cell, o));
      continue;
    }
    const ContactHalfSpace* hs = tree.halfSpace(cell.node);
    if (!hs) continue;
    const Vec3 c = tree.cellCenter(cell);
    const double r = tree.cellRadius(cell.depth);
    // Cells whose centre is closest to the +z face interior, away from the edges by more
    // than the cell size: the plane must be z = half.z.
    if (!(std::abs(c.x()) < box.half.x() - 2 * r && std::abs(c.y()) < box.half.y() - 2 * r && c.z() > box.half.z() - 0.25 * r)) continue;
    const Vec3 n(hs->normal[0], hs->normal[1], hs->normal[2]);
    EXPECT_GT(n.z(), 1.0 - 1e-6);
    EXPECT_NEAR(c.z() + hs->offset, box.half.z(), 1e-6);
    EXPECT_LT(hs->fitError, 1e-6);
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

TEST(ContactTreeBox, QueriesOutsideTheRootCubeReturnAnUpperBoundWithAnHonestError) {
  const BoxTree& box = boxTree();
  for (const Vec3& p : {Vec3(10, 0, 0), Vec3(-3, 4, 5), Vec3(0, 0, -100)}) {
    const ContactFieldSample s = box.tree.sample(p);
    const double exact = boxDistance(p, box.half);
    EXPECT_FALSE(s.insideRoot);
    EXPECT_GE(s.distance, exact - 1e-6);
    EXPECT_LE(std::abs(s.distance - exact), s.errorBound + 1e-6);
    EXPECT_TRUE(s.gradient.allFinite());
  }
}

TEST(ContactTreeBuilder, RejectsOutOfRangeSettingsNamingThem) {
  const BoxTree& box = boxTree();
  auto expectInvalid = [&](ContactTreeSettings s, const std::string& name) {
    try {
      buildContactTree(box.exact, s);
      FAIL() << name;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  };
  ContactTreeSettings s;
  s.errorRel = 0.0;
  expectInvalid(s, "errorRel");
  s = {};
  s.errorRel = std::nan("");
  expectInvalid(s, "errorRel");
  s = {};
  s.maxDepth = 21;
  expectInvalid(s, "maxDepth");
  s = {};
  s.bandRel = -1;
  expectInvalid(s, "bandRel");
  s = {};
  s.cubeMarginRel = 0.005;  // smaller than the band
  expectInvalid(s, "cubeMarginRel");
}

TEST(ContactTreeBuilder, ResultDoesNotDependOnScheduling) {
  const BoxTree& box = boxTree();
  ContactTreeSettings settings;
  settings.errorRel = 2e-3;
  const ContactTree again = buildContactTree(box.exact, settings);
  ByteWriter a, b;
  encodeContactTree(box.tree, a);
  encodeContactTree(again, b);
  EXPECT_EQ(a.bytes(), b.bytes());
}

TEST(ContactTreeCodec, RoundTripIsBitExact) {
  const BoxTree& box = boxTree();
  ByteWriter writer;
  encodeContactTree(box.tree, writer);
  ByteReader reader(writer.bytes().data(), writer.size(), "test");
  const ContactTree decoded = decodeContactTree(reader);
  EXPECT_TRUE(reader.atEnd());
  ByteWriter again;
  encodeContactTree(decoded, again);
  EXPECT_EQ(writer.bytes(), again.bytes());
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> uni(-1.5, 1.5);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 p(uni(rng), uni(rng), uni(rng));
    EXPECT_EQ(decoded.sample(p).distance, box.tree.sample(p).distance);
  }
}

TEST(ContactTreeCodec, TruncatedDataThrowsTruncatedOrCorrupt) {
  const BoxTree& box = boxTree();
  ByteWriter writer;
  encodeContactTree(box.tree, writer);
  const auto& bytes = writer.bytes();
  const std::size_t step = std::max<std::size_t>(1, bytes.size() / 3000);
  for (std::size_t size = 0; size < bytes.size(); size += step) {
    ByteReader reader(bytes.data(), size, "truncated");
    try {
      decodeContactTree(reader);
      FAIL() << "decoded " << size << " of " << bytes.size() << " bytes";
    } catch (const Error& e) {
      EXPECT_TRUE(e.code() == ErrorCode::kBakeTruncated || e.code() == ErrorCode::kBakeCorrupt) << e.what();
    }
  }
}

TEST(ContactTreeCodec, FlippedBytesEitherFailCleanlyOrGiveASafeTree) {
  const BoxTree& box = boxTree();
  ByteWriter writer;
  encodeContactTree(box.tree, writer);
  std::vector<std::byte> bytes = writer.bytes();
  std::mt19937_64 rng(11);
  const int trials = test::sanitizerRun() ? 300 : 2000;
  int rejected = 0;
  for (int trial = 0; trial < trials; ++trial) {
    std::vector<std::byte> corrupt = bytes;
    // Every header byte and array-count byte once, then random positions.
    const std::size_t at = trial < 200 ? std::size_t(trial) : rng() % corrupt.size();
    corrupt[at] ^= std::byte{static_cast<unsigned char>(1u << (rng() % 8))};
    ByteReader reader(corrupt.data(), corrupt.size(), "flipped");
    try {
      const ContactTree tree = decodeContactTree(reader);
      // A flip inside a value can leave a valid tree: every query on it must stay safe.
      for (const Vec3& p : {Vec3(0, 0, 0), Vec3(0.9, 0.5, 0.3), Vec3(5, 5, 5)}) {
        const ContactFieldSample s = tree.sample(p);
        EXPECT_TRUE(std::isfinite(s.distance));
      }
    } catch (const Error& e) {
      ++rejected;
      EXPECT_TRUE(e.code() == ErrorCode::kBakeTruncated || e.code() == ErrorCode::kBakeCorrupt ||
                  e.code() == ErrorCode::kBakeVersion)
          << e.what();
    }
  }
  EXPECT_GT(rejected, 0);
}

}  // namespace
}  // namespace clod
