// A value held on the heap with value semantics (as C++26's std::indirect): copying copies the
// value, copy-assigning assigns into the existing value (no allocation once both hold one),
// moving moves the pointer. It lets a class keep a member of a type its header only declares:
// define the class's special member functions where the type is complete.
#pragma once

#include <memory>
#include <utility>

namespace navbus::core {

template <class T>
class Indirect {
 public:
  template <class... Args>
  explicit Indirect(std::in_place_t /*construct*/, Args&&... args)
      : value_(std::make_unique<T>(std::forward<Args>(args)...)) {}
  Indirect(const Indirect& other) : value_(std::make_unique<T>(*other.value_)) {}
  Indirect(Indirect&&) noexcept = default;
  Indirect& operator=(const Indirect& other) {
    if (this == &other) return *this;
    if (value_ && other.value_) {
      *value_ = *other.value_;
    } else {
      value_ = other.value_ ? std::make_unique<T>(*other.value_) : nullptr;
    }
    return *this;
  }
  Indirect& operator=(Indirect&&) noexcept = default;
  ~Indirect() = default;

  T& operator*() { return *value_; }
  const T& operator*() const { return *value_; }
  T* operator->() { return value_.get(); }
  const T* operator->() const { return value_.get(); }

 private:
  std::unique_ptr<T> value_;
};

}  // namespace navbus::core
