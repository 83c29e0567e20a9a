// A std::vector whose resize() leaves trivially constructible elements uninitialized, for
// large arrays that are written in full right after, by several threads: their memory is
// then touched once, by the threads that fill it, instead of being zeroed first by one.
// Its storage is aligned to kHostArrayAlignment bytes, so that an OpenCL CPU device can
// use it as a buffer's memory (CL_MEM_USE_HOST_PTR; PoCL asks for 128).
#pragma once

#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace candela {

constexpr size_t kHostArrayAlignment = 128;

template <class T>
struct DefaultInitAllocator : std::allocator<T> {
  using value_type = T;
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <class U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
  T* allocate(size_t n) {
    if (n > size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(kHostArrayAlignment)));
  }
  void deallocate(T* p, size_t) noexcept { ::operator delete(p, std::align_val_t(kHostArrayAlignment)); }
  // Default-initialization: nothing is written for a trivially constructible U
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

template <class T>
using UninitVector = std::vector<T, DefaultInitAllocator<T>>;

}  // namespace candela
