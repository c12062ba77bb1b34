#include "navbus/core/filter/pseudorange_error_slots.hpp"

#include <algorithm>

namespace navbus::core {

void PseudorangeErrorSlots::clear() {
  sv_of_slot_.fill(kFree);
  errors_m_.setZero();
}

void PseudorangeErrorSlots::leaveStatesToSecondClock(bool leave) {
  static_assert(layout::kSecondClockBias.index == layout::kPseudorangeError.end() - 2);
  slots_in_use_ = leave ? kSlots - 2 : kSlots;
  clear();
}

const PseudorangeErrorSlots::Assignment& PseudorangeErrorSlots::assign(
    const std::vector<int>& sv_ids) {
  // Release: a satellite missing from this epoch gives its state up.
  for (int s = 0; s < slots_in_use_; ++s) {
    const auto i = static_cast<std::size_t>(s);
    if (sv_of_slot_[i] != kFree &&
        std::find(sv_ids.begin(), sv_ids.end(), sv_of_slot_[i]) == sv_ids.end()) {
      sv_of_slot_[i] = kFree;
      errors_m_[s] = 0.0;
    }
  }
  assignment_.state_index.clear();
  assignment_.fresh.clear();
  for (const int sv : sv_ids) {
    const auto in_use = sv_of_slot_.begin() + slots_in_use_;
    const auto held = std::find(sv_of_slot_.begin(), in_use, sv);
    if (held != in_use) {
      assignment_.state_index.push_back(layout::kPseudorangeError.index +
                                        static_cast<int>(held - sv_of_slot_.begin()));
      continue;
    }
    const auto free = std::find(sv_of_slot_.begin(), in_use, kFree);
    if (free == in_use) {
      assignment_.state_index.push_back(-1);
      ++unmodelled_;
      continue;
    }
    *free = sv;
    const int index =
        layout::kPseudorangeError.index + static_cast<int>(free - sv_of_slot_.begin());
    errors_m_[slot(index)] = 0.0;
    assignment_.state_index.push_back(index);
    assignment_.fresh.push_back(index);
  }
  return assignment_;
}

}  // namespace navbus::core
