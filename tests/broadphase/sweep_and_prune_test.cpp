#include <random>

#include <gtest/gtest.h>

#include "clod/broadphase.h"

namespace clod {
namespace {

bool overlapsBrute(const Aabb& a, const Aabb& b) {
  if (a.empty() || b.empty()) return false;
  for (int k = 0; k < 3; ++k)
    if (a.min[k] > b.max[k] || b.min[k] > a.max[k]) return false;
  return true;
}

TEST(SweepAndPrune, FindsExactlyThePairsBruteForceFinds) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(-10.0, 10.0), size(0.1, 2.0);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Aabb> boxes(300);
    std::vector<std::uint8_t> active(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      const Vec3 c(pos(rng), pos(rng) * (trial % 3 == 0 ? 0.1 : 1.0), pos(rng));
      const Vec3 h(size(rng), size(rng), size(rng));
      boxes[i].min = c - h;
      boxes[i].max = c + h;
      active[i] = (i % 4 != 0);
    }
    boxes[5] = Aabb{};  // an empty box overlaps nothing
    std::vector<BodyPair> expected;
    for (std::uint32_t i = 0; i < boxes.size(); ++i)
      for (std::uint32_t j = i + 1; j < boxes.size(); ++j)
        if ((active[i] || active[j]) && overlapsBrute(boxes[i], boxes[j])) expected.push_back({i, j});
    std::vector<BodyPair> pairs;
    BroadPhaseScratch scratch;
    findOverlappingPairs(boxes, active.data(), pairs, scratch);
    EXPECT_EQ(pairs, expected) << "trial " << trial;
  }
}

// The pair limit: a pile of n boxes at one point has n(n-1)/2 pairs (counted by brute force);
// a limit of that many finds them all, one less stops early and says so.
TEST(SweepAndPrune, StopsOnceMorePairsThanTheLimitAreFound) {
  std::vector<Aabb> boxes(40);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    boxes[i].min = Vec3(-1.0, -1.0, -1.0) + 0.01 * double(i) * Vec3::Ones();
    boxes[i].max = boxes[i].min + Vec3(2.0, 2.0, 2.0);
  }
  std::size_t expected = 0;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    for (std::size_t j = i + 1; j < boxes.size(); ++j) expected += overlapsBrute(boxes[i], boxes[j]);
  ASSERT_EQ(expected, boxes.size() * (boxes.size() - 1) / 2);
  std::vector<BodyPair> pairs;
  BroadPhaseScratch scratch;
  EXPECT_TRUE(findOverlappingPairs(boxes, nullptr, pairs, scratch, expected));
  EXPECT_EQ(pairs.size(), expected);
  EXPECT_FALSE(findOverlappingPairs(boxes, nullptr, pairs, scratch, expected - 1));
  EXPECT_EQ(pairs.size(), expected);  // it stopped at the first pair past the limit
}

TEST(SweepAndPrune, TouchingBoxesCountAsOverlapping) {
  std::vector<Aabb> boxes(2);
  boxes[0].min = Vec3(0, 0, 0);
  boxes[0].max = Vec3(1, 1, 1);
  boxes[1].min = Vec3(1, 0, 0);
  boxes[1].max = Vec3(2, 1, 1);
  std::vector<BodyPair> pairs;
  BroadPhaseScratch scratch;
  findOverlappingPairs(boxes, nullptr, pairs, scratch);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0], (BodyPair{0, 1}));
}

}  // namespace
}  // namespace clod
