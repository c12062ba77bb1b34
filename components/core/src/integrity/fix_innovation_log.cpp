#include "navbus/core/integrity/fix_innovation_log.hpp"

#include <algorithm>

namespace navbus::core {

void FixInnovationLog::add(const FixInnovation& f) {
  const auto keep_end =
      std::lower_bound(records_.begin(), records_.end(), f.time_ns,
                       [](const FixInnovation& x, std::int64_t t) { return x.time_ns < t; });
  dropped_ += static_cast<std::uint64_t>(records_.end() - keep_end);
  records_.erase(keep_end, records_.end());
  records_.push_back(f);
}

}  // namespace navbus::core
