// The command line's heap settings (apps/heap_settings.h): applied on glibc, refused when a value
// does not fit mallopt's int, and memory still allocates and frees after them.
#include "apps/heap_settings.h"

#include <cstring>
#include <memory>

#include <gtest/gtest.h>

namespace auvdock::cli {
namespace {

TEST(HeapSettingsTest, AppliesTheDefaultsOnGlibc) {
#if defined(__GLIBC__)
  EXPECT_TRUE(ApplyHeapSettings());
#else
  EXPECT_FALSE(ApplyHeapSettings());
#endif
  // An image-sized buffer, below the mmap threshold now, allocates, fills and frees as before.
  const std::size_t bytes = std::size_t{16} << 20;
  std::unique_ptr<unsigned char[]> buffer(new unsigned char[bytes]);
  std::memset(buffer.get(), 7, bytes);
  EXPECT_EQ(buffer[bytes - 1], 7);
}

TEST(HeapSettingsTest, RefusesValuesThatDoNotFitMallopt) {
  HeapSettings too_large;
  too_large.trim_threshold_bytes = std::size_t{1} << 40;
  EXPECT_FALSE(ApplyHeapSettings(too_large));
  HeapSettings mmap_too_large;
  mmap_too_large.mmap_threshold_bytes = std::size_t{1} << 40;
  EXPECT_FALSE(ApplyHeapSettings(mmap_too_large));
}

}  // namespace
}  // namespace auvdock::cli
