#include "navbus/nav_filter/solution_flags.hpp"

#include <algorithm>

#include <spdlog/spdlog.h>

namespace navbus::nav_filter {

namespace {
constexpr std::uint32_t kStreamLostFlags =
    navbus::FAULT_IMU_STREAM_LOST | navbus::FAULT_GNSS_STREAM_LOST | navbus::FAULT_ST_STREAM_LOST |
    navbus::FAULT_RAW_IMU_LOST;
}  // namespace

std::optional<std::uint32_t> SolutionFlags::streamFlag(const navbus::FilterCommand& c,
                                                       const InputIds& ids) {
  const auto is = [&c](const std::optional<std::uint32_t>& id) {
    return id && *id == c.sensor_id();
  };
  switch (c.sensor()) {
    case navbus::SOURCE_IMU_STREAM:
      if (c.sensor_id() != ids.imu) return std::nullopt;
      return navbus::FAULT_IMU_STREAM_LOST;
    case navbus::SOURCE_IMU_RAW_STREAM:
      return navbus::FAULT_RAW_IMU_LOST;
    case navbus::SOURCE_GNSS_OBS_STREAM:
      if (!is(ids.gnss_observations) && !is(ids.second_gnss_observations)) return std::nullopt;
      return navbus::FAULT_GNSS_STREAM_LOST;
    case navbus::SOURCE_GNSS_FIX_STREAM:
      if (!is(ids.gnss_fix)) return std::nullopt;
      return navbus::FAULT_GNSS_STREAM_LOST;
    case navbus::SOURCE_ST_STREAM:
      if (!is(ids.star_tracker)) return std::nullopt;
      return navbus::FAULT_ST_STREAM_LOST;
    default:
      return std::nullopt;
  }
}

void SolutionFlags::applyStreamCommand(const navbus::FilterCommand& c, std::uint32_t flag) {
  const bool lost = c.kind() == navbus::CMD_EXCLUDE_STREAM;
  const int source = static_cast<int>(c.sensor());
  lost_.erase(std::remove_if(
                  lost_.begin(), lost_.end(),
                  [&](const LostStream& l) { return l.source == source && l.id == c.sensor_id(); }),
              lost_.end());
  if (lost) lost_.push_back({source, c.sensor_id(), flag});
  stream_flags_ = 0;
  for (const LostStream& l : lost_) stream_flags_ |= l.flag;
  spdlog::log(lost ? spdlog::level::warn : spdlog::level::info,
              "stream source {} id {} {}; flags 0x{:x}", static_cast<int>(c.sensor()),
              c.sensor_id(), lost ? "lost" : "restored", stream_flags_);
}

void SolutionFlags::setFaultMonitorAlive(bool alive) {
  const std::uint32_t flags = alive ? 0 : navbus::FAULT_NO_FAULT_MONITOR;
  if (flags == monitor_flags_) return;
  monitor_flags_ = flags;
  if (alive) {
    spdlog::info("a fault monitor is alive again: faults are monitored");
  } else {
    ++monitor_losses_;
    spdlog::warn("no fault monitor is alive: solutions flagged FAULT_NO_FAULT_MONITOR");
  }
}

bool SolutionFlags::degraded() const {
  return (stream_flags_ & kStreamLostFlags) != 0 || monitor_flags_ != 0;
}

}  // namespace navbus::nav_filter
