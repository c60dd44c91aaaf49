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
#include <cstdint>
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
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    // Whole huge pages, aligned to them, so that every page of the array
    // can be one: mapped with a huge page to spare, whose unaligned ends go
    // back. (Not malloc's aligned allocation: its header just before the
    // array would take a huge page of its own.)
    const std::size_t rounded = Rounded(bytes);
    void* mapped = mmap(nullptr, rounded + kHugePageBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mapped == MAP_FAILED) throw std::bad_alloc();
    const std::uintptr_t start = (reinterpret_cast<std::uintptr_t>(mapped) + kHugePageBytes - 1) & ~(kHugePageBytes - 1);
    const std::size_t head = start - reinterpret_cast<std::uintptr_t>(mapped);
    if (head > 0) munmap(mapped, head);
    if (head < kHugePageBytes) munmap(reinterpret_cast<void*>(start + rounded), kHugePageBytes - head);
    madvise(reinterpret_cast<void*>(start), rounded, MADV_HUGEPAGE);  // a hint: where it is refused, ordinary pages
    return reinterpret_cast<T*>(start);
#else
    return static_cast<T*>(::operator new(bytes));
#endif
  }

  void deallocate(T* memory, std::size_t n) noexcept {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (n * sizeof(T) >= kHugePageBytes) {
      munmap(memory, Rounded(n * sizeof(T)));
      return;
    }
#endif
    ::operator delete(memory);
  }

  template <typename U>
  bool operator==(const LargeBufferAllocator<U>&) const noexcept {
    return true;
  }
  template <typename U>
  bool operator!=(const LargeBufferAllocator<U>&) const noexcept {
    return false;
  }

 private:
  static std::size_t Rounded(std::size_t bytes) { return (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes; }
};

// A vector of a large array.
template <typename T>
using LargeBuffer = std::vector<T, LargeBufferAllocator<T>>;

}  // namespace skybake
