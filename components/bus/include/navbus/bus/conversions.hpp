// IDL <-> core conversions. Units are converted here, once; the core works in SI.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include <navbus_idl/Gnss.h>
#include <navbus_idl/Imu.h>
#include <navbus_idl/Navigation.h>
#include <navbus_idl/StarTracker.h>

#include "navbus/bus/validation.hpp"
#include "navbus/core/engine/navigation_engine.hpp"
#include "navbus/core/filter/epoch_diagnostics.hpp"
#include "navbus/core/gnss/gnss_measurement.hpp"
#include "navbus/core/ins/strapdown.hpp"
#include "navbus/core/integrity/glr.hpp"

namespace navbus::bus {

inline std::array<double, 3> toArray(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}
inline Eigen::Vector3d toVector(const std::array<double, 3>& a) {
  return {a[0], a[1], a[2]};
}

core::ImuIncrement toCore(const navbus::ImuIncrement& msg);
navbus::ImuIncrement toIdl(const core::ImuIncrement& inc, std::uint32_t sensor_id,
                           std::uint64_t seq);

core::GnssFixMeasurement toCore(const navbus::GnssFix& msg);
/// The attitude quaternion is renormalized (validation admits |q| within 1e-6 of one).
core::StarAttitudeMeasurement toCore(const navbus::StarTrackerAttitude& msg);
/// The valid satellites of an epoch with the satellite clock corrections applied, so that the
/// core sees corrected pseudoranges and rates.
std::vector<core::SatelliteObservation> toCore(const navbus::GnssObservationEpoch& msg);
/// The same without the satellites screenSatellites() dropped.
std::vector<core::SatelliteObservation> toCore(const navbus::GnssObservationEpoch& msg,
                                               const std::vector<SatelliteRejection>& dropped);
/// The same into `out` (cleared first; its storage reused).
void toCore(const navbus::GnssObservationEpoch& msg, const std::vector<SatelliteRejection>& dropped,
            std::vector<core::SatelliteObservation>& out);

/// The tightly coupled filter's state layout (core::layout) as the diagnostics declare it.
void fillStateLayout(navbus::FilterDiagnostics& msg);

/// The bus ids of a filter's fused receivers, in receiver order (0: none).
using FusedReceiverIds = std::array<std::uint32_t, core::layout::kMaxFusedReceivers>;

/// A GNSS epoch's diagnostics over core::layout as the message (matrices row-major); each
/// pseudorange row names its receiver by `receiver_ids`.
navbus::FilterDiagnostics toIdl(const core::EpochDiagnostics& d, std::uint32_t vehicle_id,
                                std::uint64_t seq, std::int64_t time_ns,
                                const FusedReceiverIds& receiver_ids = {});

/// A validated diagnostics sample (validate() passed) as the GLR's epoch; a rejection when
/// its state layout is not core::layout's or it has more rows than the GLR supports.
std::optional<Rejection> toGlrEpoch(const navbus::FilterDiagnostics& msg, core::GlrEpoch& out);

/// Fills time, position, velocity and attitude fields of a solution from a navigation state.
void fillSolution(const core::NavState& state, navbus::NavigationSolution& out);
/// The navigation state a solution carries (time, position, velocity, attitude).
core::NavState toCore(const navbus::NavigationSolution& solution);

}  // namespace navbus::bus
