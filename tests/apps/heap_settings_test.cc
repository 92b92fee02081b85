// The command line's heap settings (apps/heap_settings.h): applied on glibc, refused when a value
// does not fit mallopt's int, and memory still allocates and frees after them.
#include "apps/heap_settings.h"

#include <cstring>
#include <memory>

#include <gtest/gtest.h>

// AddressSanitizer's allocator replaces glibc's: its mallopt accepts nothing (returns 0).
#if defined(__SANITIZE_ADDRESS__)
#define AUVDOCK_TEST_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define AUVDOCK_TEST_UNDER_ASAN 1
#endif
#endif

namespace auvdock::cli {
namespace {

TEST(HeapSettingsTest, AppliesTheDefaultsOnGlibc) {
#if defined(__GLIBC__) && !defined(AUVDOCK_TEST_UNDER_ASAN)
  EXPECT_TRUE(ApplyHeapSettings());
#else
  ApplyHeapSettings();  // refused or not, the program goes on
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
