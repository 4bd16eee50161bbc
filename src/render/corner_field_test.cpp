#include "render/corner_field.hpp"

#include <gtest/gtest.h>

#include <cmath>
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

// Every snapshot frees its corner copies and asks for blocks of the same sizes: the freed blocks are
// handed out again (no page fault, no zeroing by the kernel), at most kIdleHugeBlocks of them kept.
TEST(CornerField, FreedLargeBlocksAreReusedForTheSameSize) {
  release_idle_huge_blocks();
  constexpr std::size_t kMiB = std::size_t(1) << 20;
  void* a = allocate_huge(5 * kMiB);
  deallocate_huge(a);
  EXPECT_EQ(idle_huge_bytes(), 6 * kMiB);  // rounded to whole 2 MiB pages
  void* b = allocate_huge(5 * kMiB + 100);  // the same rounded size
  EXPECT_EQ(a, b);
  EXPECT_EQ(idle_huge_bytes(), 0u);
  void* c = allocate_huge(9 * kMiB);  // another size: a new block
  EXPECT_NE(c, b);
  std::vector<void*> more;
  for (std::size_t i = 0; i < kIdleHugeBlocks + 2; ++i) more.push_back(allocate_huge(2 * kMiB));
  for (void* p : more) deallocate_huge(p);
  EXPECT_EQ(idle_huge_bytes(), kIdleHugeBlocks * 2 * kMiB);  // the oldest went back to the system
  void* small = allocate_huge(1000);  // below 2 MiB: plain malloc, never kept
  deallocate_huge(small);
  EXPECT_EQ(idle_huge_bytes(), kIdleHugeBlocks * 2 * kMiB);
  deallocate_huge(b);
  deallocate_huge(c);
  release_idle_huge_blocks();
  EXPECT_EQ(idle_huge_bytes(), 0u);
}

// A joint copy holds, record by record, exactly the values of the two separate copies (so the
// march reads the same numbers from either), with the same quantization.
TEST(CornerField, JointCopyInterleavesTheTwoSeparateCopies) {
  const GridGeometry g{{9, 7, 5}, {0, 0, 0}, {1, 1, 1}};
  std::vector<float> a(std::size_t(9 * 7 * 5)), b(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) a[i] = std::sin(0.37f * float(i)), b[i] = 3.0f * std::cos(0.11f * float(i)) - 1;
  const FieldView va = FieldView::whole(g, a.data()), vb = FieldView::whole(g, b.data());
  const CornerField sa(va), sb(vb);
  const auto [ja, jb] = CornerField::joint(va, vb);
  ASSERT_EQ(ja.record(), 16);
  ASSERT_EQ(sa.record(), 8);
  ASSERT_EQ(ja.counts(), sa.counts());
  EXPECT_EQ(ja.offset(), sa.offset());
  EXPECT_EQ(ja.scale(), sa.scale());
  EXPECT_EQ(jb.offset(), sb.offset());
  EXPECT_EQ(jb.scale(), sb.scale());
  EXPECT_EQ(jb.data(), ja.data() + 8);
  EXPECT_EQ(ja.bytes(), sa.bytes());
  const std::size_t cells = std::size_t(sa.counts()[0]) * sa.counts()[1] * sa.counts()[2];
  for (std::size_t c = 0; c < cells; ++c)
    for (int v = 0; v < 8; ++v) {
      ASSERT_EQ(ja.data()[16 * c + v], sa.data()[8 * c + v]) << "cell " << c;
      ASSERT_EQ(jb.data()[16 * c + v], sb.data()[8 * c + v]) << "cell " << c;
    }
}

}  // namespace
}  // namespace panoptes::render
