// Whether a fault monitor is alive, from the arrival times of its periodic reports (the fault
// manager's health on the bus): alive while its latest report is at most `timeout` old, and
// during the first `timeout` after start, when it may not have reported yet. Pure logic: the
// caller supplies its clock.
#pragma once

#include <cstdint>

namespace navbus::nav_filter {

class MonitorLiveness {
 public:
  MonitorLiveness(std::int64_t timeout_ns, std::int64_t start_ns)
      : timeout_ns_(timeout_ns), last_report_ns_(start_ns) {}

  void onReport(std::int64_t now_ns) {
    last_report_ns_ = now_ns;
    ++reports_;
  }
  bool alive(std::int64_t now_ns) const { return now_ns - last_report_ns_ <= timeout_ns_; }
  std::uint64_t reports() const { return reports_; }

 private:
  std::int64_t timeout_ns_;
  std::int64_t last_report_ns_;  ///< the start time until the first report
  std::uint64_t reports_{0};
};

}  // namespace navbus::nav_filter
