// A working buffer that belongs to its owner's computation, not to its state: a copy of the
// owner starts without one, and an assignment to the owner keeps the target's own. The filter's
// recovery history keeps dozens of copies of the navigation engine (snapshots to restore it to
// before a fault's onset); buffers that every step overwrites before it reads them need not be
// in those copies. The buffer lives on the heap, made at its first use (so that even a buffer of
// fixed size, e.g. a 48 x 48 matrix, costs a copy nothing); the owner sizes it before each use
// (a no-op once sized): only an owner's first use allocates, and a copy's.
#pragma once

#include <memory>

namespace navbus::core {

template <class T>
class Scratch {
 public:
  Scratch() = default;
  Scratch(const Scratch& /*other*/) {}
  Scratch(Scratch&&) noexcept = default;
  Scratch& operator=(const Scratch& /*other*/) { return *this; }
  Scratch& operator=(Scratch&& /*other*/) noexcept { return *this; }
  ~Scratch() = default;

  T& operator*() const { return get(); }
  T* operator->() const { return &get(); }

 private:
  // The buffer is not part of the owner's observable state, so a const owner may make it.
  T& get() const {
    if (!value_) value_ = std::make_unique<T>();
    return *value_;
  }
  mutable std::unique_ptr<T> value_;
};

}  // namespace navbus::core
