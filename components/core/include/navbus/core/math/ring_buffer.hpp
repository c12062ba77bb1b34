// A FIFO on one buffer that grows but never shrinks: push at the back, pop at the front, index
// from the front. Popped slots keep their objects, and a push assigns to them, so that members
// keep their capacity: a steady state (as many pops as pushes) allocates nothing. Used where a
// std::deque would allocate a block every few pushes (the filter's recovery history, the
// low-latency output's increments).
#pragma once

#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

namespace navbus::core {

template <class T>
class RingBuffer {
 public:
  explicit RingBuffer(std::size_t capacity = 16) : slots_(capacity > 0 ? capacity : 1) {}

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }

  /// Element i from the front.
  T& operator[](std::size_t i) { return *slots_[slot(i)]; }
  const T& operator[](std::size_t i) const { return *slots_[slot(i)]; }
  T& front() { return (*this)[0]; }
  const T& front() const { return (*this)[0]; }
  T& back() { return (*this)[size_ - 1]; }
  const T& back() const { return (*this)[size_ - 1]; }

  /// Appends a copy (assigned to a reused slot where there is one); grows when full.
  template <class U>
  void push_back(U&& value) {
    if (size_ == slots_.size()) grow();
    slots_[slot(size_)] = std::forward<U>(value);
    ++size_;
  }
  /// Appends in place: `assign(slot)` on a reused slot (its members keep their capacity),
  /// else a slot made by `make()`.
  template <class Make, class Assign>
  void push_back_reusing(Make&& make, Assign&& assign) {
    if (size_ == slots_.size()) grow();
    std::optional<T>& s = slots_[slot(size_)];
    if (s) {
      assign(*s);
    } else {
      s.emplace(make());
    }
    ++size_;
  }
  /// Makes the buffer hold at least `n` slots, each with an object made by `make()` where it has
  /// none, so that the next pushes up to `n` only assign: objects that own memory allocate here,
  /// once, rather than one by one as the buffer fills.
  template <class Make>
  void prefill(std::size_t n, Make&& make) {
    if (slots_.size() < n) reslot(n);  // exactly n: each slot costs an object
    for (std::optional<T>& s : slots_) {
      if (!s) s.emplace(make());
    }
  }
  /// The object the next push_back assigns to (an element popped or truncated before, whose
  /// storage the caller may take first), or nullptr when that slot is empty or the buffer grows.
  T* nextSlot() {
    if (size_ == slots_.size()) return nullptr;
    std::optional<T>& s = slots_[slot(size_)];
    return s ? &*s : nullptr;
  }
  void pop_front() {
    head_ = slot(1);
    --size_;
  }
  /// Keeps the first n elements.
  void truncate(std::size_t n) {
    if (n < size_) size_ = n;
  }
  void clear() {
    head_ = 0;
    size_ = 0;
  }

 private:
  std::size_t slot(std::size_t i) const { return (head_ + i) % slots_.size(); }
  void grow() { reslot(2 * slots_.size()); }
  /// Moves the elements, oldest first, into `n` slots.
  void reslot(std::size_t n) {
    std::vector<std::optional<T>> bigger(n);
    for (std::size_t i = 0; i < slots_.size(); ++i) bigger[i] = std::move(slots_[slot(i)]);
    slots_ = std::move(bigger);
    head_ = 0;
  }

  std::vector<std::optional<T>> slots_;
  std::size_t head_{0};
  std::size_t size_{0};
};

}  // namespace navbus::core
