// The C library's heap settings for the command line: keep the memory that each frame's image
// buffers free for the next frame instead of handing it back to the kernel.
//
// Why: a frame's detection allocates and frees tens of megabyte-sized buffers (the luma, the
// scale-space pyramid and responses, OpenCV's filter scratch; the image prefetcher's thread
// decodes into its own arena). With glibc's defaults (a dynamic mmap threshold that starts at
// 128 KiB, the free top of a heap trimmed beyond twice that) much of it goes back to the kernel
// at every frame, and the next frame takes a page fault for every 4 KiB page of it again. On the
// pool clip (720 x 576 JPEG) `auvdock detect` spent 38 % of its time in page faults and took
// 43.5 ms per frame instead of 9.4 ms (100 frames: 373 000 minor faults against 8 000).
//
// The settings: allocations up to mmap_threshold come from the heap (an image of 1280 x 1024 x 3
// floats is 15 MiB), and up to trim_threshold of free memory stays in it. The peak resident size
// hardly changes (the pool clip: 77 -> 80 MiB); a library user with their own main() can do the
// same (mallopt, or GLIBC_TUNABLES=glibc.malloc.mmap_threshold=...:glibc.malloc.trim_threshold=...).
// No effect outside glibc.
#pragma once

#include <cstddef>

namespace auvdock::cli {

struct HeapSettings {
  std::size_t mmap_threshold_bytes = std::size_t{32} << 20;
  std::size_t trim_threshold_bytes = std::size_t{64} << 20;
};

// Applies the settings to the process's allocator (glibc's mallopt). Returns false where that is
// not possible (another C library, a sanitizer's allocator, or glibc refused a value); the program
// works either way.
bool ApplyHeapSettings(const HeapSettings& settings = {});

}  // namespace auvdock::cli
