#include "render/corner_field.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <vector>

namespace panoptes::render {
namespace {

// Large copies come in 2 MiB-aligned blocks (so that madvise(MADV_HUGEPAGE) can back them with huge
// pages); small ones from malloc; both hold and keep what is written to them.
TEST(CornerField, HugePageAllocatorAlignsLargeBlocksAndKeepsContents) {
  std::vector<std::uint16_t, HugePageAllocator<std::uint16_t>> big(3 << 20);  // 6 MiB
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(big.data()) % (std::uintptr_t(2) << 20), 0u);
  std::iota(big.begin(), big.end(), std::uint16_t(0));
  for (std::size_t i = 0; i < big.size(); i += 4099) ASSERT_EQ(big[i], std::uint16_t(i));
  std::vector<std::uint16_t, HugePageAllocator<std::uint16_t>> small(100, 7);
  EXPECT_EQ(small[99], 7);
  big = small;  // reallocation through the allocator
  EXPECT_EQ(big.size(), 100u);
  EXPECT_EQ(big[0], 7);
}

}  // namespace
}  // namespace panoptes::render
