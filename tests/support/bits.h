// Bit-for-bit comparisons for tests: "the same image" means the same float bits, not values
// within a tolerance (-0.0 differs from 0.0, and two NaNs with the same bits are equal).
#pragma once

#include <cstring>
#include <type_traits>
#include <vector>

namespace test_support {

// Two float buffers (images, depths, hit ids) of the same length with the same bits.
inline bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

// Two plain values (a float, a struct of floats) with the same bits.
template <class T>
requires std::is_trivially_copyable_v<T>
bool same_bits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

}  // namespace test_support
