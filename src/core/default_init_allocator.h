// An allocator for flat arrays that are always written before they are read.
#pragma once

#include <cstddef>
#include <memory>
#include <new>
#include <utility>
#include <vector>

namespace qem::core {

/// std::allocator whose resize() leaves new elements uninitialised: arrays that grow by
/// stretches always written before they are read (vertex_lists.h's arena, a tree's triangles)
/// skip the zero fill: a measurable share of each pass, and on a large array a serial pass over
/// fresh pages that the threads filling it would otherwise touch first, side by side.
template <class T>
struct DefaultInitAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <class U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

/// A vector of such elements: resize() leaves them unwritten.
template <class T>
using UnzeroedVector = std::vector<T, DefaultInitAllocator<T>>;

/// As DefaultInitAllocator, its blocks aligned to Align bytes: for arrays read a cache line at a
/// time (the surface tree's pairs of nodes), which malloc aligns to 16 bytes only.
template <class T, std::size_t Align>
struct AlignedDefaultInitAllocator : DefaultInitAllocator<T> {
  using value_type = T;
  template <class U>
  struct rebind {
    using other = AlignedDefaultInitAllocator<U, Align>;
  };
  AlignedDefaultInitAllocator() = default;
  template <class U>
  AlignedDefaultInitAllocator(const AlignedDefaultInitAllocator<U, Align>&) noexcept {}
  T* allocate(std::size_t n) {
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(Align)));
  }
  void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, std::align_val_t(Align)); }
};

}  // namespace qem::core
