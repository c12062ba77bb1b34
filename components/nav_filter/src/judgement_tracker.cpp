#include "navbus/nav_filter/judgement_tracker.hpp"

#include <algorithm>

namespace navbus::nav_filter {

std::optional<std::int64_t> JudgementTracker::onProgress(
    const navbus::FaultMonitorProgress& report) {
  ++reports_;
  held_ = report;
  const std::optional<std::int64_t> judged = release();
  if (!judged) ++held_for_command_;
  return judged;
}

std::optional<std::int64_t> JudgementTracker::onCommand(const navbus::FilterCommand& command) {
  std::uint64_t& latest = latest_command_id_[Run{command.issuer().to_string(), command.run_id()}];
  latest = std::max(latest, command.command_id());
  return release();
}

std::optional<std::int64_t> JudgementTracker::release() {
  if (!held_) return std::nullopt;
  if (held_->last_command_id() > 0) {
    const auto it = latest_command_id_.find(Run{held_->issuer().to_string(), held_->run_id()});
    if (it == latest_command_id_.end() || it->second < held_->last_command_id())
      return std::nullopt;
  }
  const auto judged = static_cast<std::int64_t>(held_->judged_up_to_gps_ns());
  imu_judged_ns_ =
      std::max(imu_judged_ns_, static_cast<std::int64_t>(held_->imu_judged_up_to_gps_ns()));
  gnss_judged_ns_ =
      std::max(gnss_judged_ns_, static_cast<std::int64_t>(held_->gnss_judged_up_to_gps_ns()));
  held_.reset();
  return judged;
}

}  // namespace navbus::nav_filter
