// A working buffer that belongs to its owner's computation, not to its state: a copy of the
// owner starts with an empty one, and an assignment to the owner keeps the target's own. The
// filter's recovery history keeps dozens of copies of the navigation engine (snapshots to
// restore it to before a fault's onset); buffers that every step overwrites before it reads them
// need not be in those copies. The owner sizes the buffer before each use (a no-op once sized):
// only a copy's first use allocates.
#pragma once

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

  T& operator*() { return value_; }
  const T& operator*() const { return value_; }
  T* operator->() { return &value_; }
  const T* operator->() const { return &value_; }

 private:
  T value_{};
};

}  // namespace navbus::core
