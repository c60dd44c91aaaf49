// Storage for the bake's large arrays (its tables and their working copies,
// several of tens of MiB each): memory the kernel may back with 2 MiB pages
// (transparent huge pages, which Linux gives where they are asked for with
// madvise), so that touching it the first time costs one page fault per
// 2 MiB instead of one per 4 KiB. A bake touches each of its arrays once,
// fresh: most of its page faults, and a tenth of its time, were those
// first touches (docs/benchmark.md, tenth round). Allocations under 2 MiB,
// and systems without madvise, get ordinary memory.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace skybake {

inline constexpr std::size_t kHugePageBytes = std::size_t(2) << 20;

// A std::allocator for vectors of large arrays (LargeBuffer, below).
template <typename T>
struct LargeBufferAllocator {
  using value_type = T;

  LargeBufferAllocator() = default;
  template <typename U>
  LargeBufferAllocator(const LargeBufferAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > std::size_t(-1) / sizeof(T)) throw std::bad_alloc();
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kHugePageBytes) return static_cast<T*>(::operator new(bytes));
    // Whole huge pages, aligned to them, so that every page of the array can be one.
    const std::size_t rounded = (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
    void* memory = std::aligned_alloc(kHugePageBytes, rounded);
    if (memory == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    madvise(memory, rounded, MADV_HUGEPAGE);  // a hint: where it is refused, ordinary pages
#endif
    return static_cast<T*>(memory);
  }

  void deallocate(T* memory, std::size_t n) noexcept {
    if (n * sizeof(T) < kHugePageBytes) {
      ::operator delete(memory);
    } else {
      std::free(memory);
    }
  }

  template <typename U>
  bool operator==(const LargeBufferAllocator<U>&) const noexcept {
    return true;
  }
  template <typename U>
  bool operator!=(const LargeBufferAllocator<U>&) const noexcept {
    return false;
  }
};

// A vector of a large array.
template <typename T>
using LargeBuffer = std::vector<T, LargeBufferAllocator<T>>;

}  // namespace skybake
