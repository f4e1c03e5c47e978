#pragma once
// An open-addressing hash map from a packed grid position (< 2^63) to a small value: the contact
// tree codec's per-level lookups of the cells and lattice points coded so far
// (contact_tree_codec.cpp). Linear probing at most half full; clear() keeps the capacity, so a
// walk over the levels allocates only while the largest level grows it. std::unordered_map
// allocated a node per entry there and made decoding a bake 65 % slower than without lookups.

#include <cstdint>
#include <vector>

namespace clod::detail {

template <class Value>
class PositionMap {
public:
  void clear() {
    if (size_ == 0) return;
    keys_.assign(keys_.size(), kEmpty);
    size_ = 0;
  }
  const Value* find(std::uint64_t key) const {
    if (keys_.empty()) return nullptr;
    for (std::size_t i = slot(key);; i = (i + 1) & mask_) {
      if (keys_[i] == key) return &values_[i];
      if (keys_[i] == kEmpty) return nullptr;
    }
  }
  /// Adds key -> value unless the key is present (the first value stays).
  void insert(std::uint64_t key, const Value& value) {
    if (2 * (size_ + 1) > keys_.size()) grow();
    for (std::size_t i = slot(key);; i = (i + 1) & mask_) {
      if (keys_[i] == key) return;
      if (keys_[i] == kEmpty) {
        keys_[i] = key;
        values_[i] = value;
        ++size_;
        return;
      }
    }
  }

private:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // no position packs to this
  std::size_t slot(std::uint64_t key) const { return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_); }
  void grow() {
    std::vector<std::uint64_t> keys = std::move(keys_);
    std::vector<Value> values = std::move(values_);
    const std::size_t capacity = keys.empty() ? 1024 : 2 * keys.size();
    keys_.assign(capacity, kEmpty);
    values_.assign(capacity, Value{});
    mask_ = capacity - 1;
    shift_ = 64;
    for (std::size_t c = capacity; c > 1; c >>= 1) --shift_;
    size_ = 0;
    for (std::size_t i = 0; i < keys.size(); ++i)
      if (keys[i] != kEmpty) insert(keys[i], values[i]);
  }

  std::vector<std::uint64_t> keys_;
  std::vector<Value> values_;
  std::size_t mask_ = 0;
  int shift_ = 64;
  std::size_t size_ = 0;
};

}  // namespace clod::detail
