#include "navbus/nav_filter/solution_messages.hpp"

#include <cmath>
#include <sstream>

#include "navbus/bus/conversions.hpp"

namespace navbus::nav_filter {

navbus::NavigationSolution buildSolution(const core::NavigationEngine& engine,
                                         std::uint32_t vehicle_id, std::uint64_t seq,
                                         std::uint32_t pipeline_flags, bool fault_monitor_alive) {
  const core::EngineConfig& config = engine.config();
  navbus::NavigationSolution sol;
  sol.vehicle_id(vehicle_id);
  sol.seq(seq);
  bus::fillSolution(engine.state(), sol);
  // Sigmas from the filter covariance: propagated only (inertial-only mode) or updated.
  const core::StateMatrix& P = engine.covariance();
  auto sigma3 = [&P](const core::StateBlock& b) {
    return bus::toArray(P.block<3, 3>(b.index, b.index).diagonal().cwiseSqrt());
  };
  sol.pos_sigma_ned_m(sigma3(core::layout::kPos));
  sol.vel_sigma_ned_mps(sigma3(core::layout::kVel));
  sol.att_sigma_ned_rad(sigma3(core::layout::kAtt));
  sol.accel_bias_sigma_b_mps2(sigma3(core::layout::kAccelBias));
  sol.gyro_bias_sigma_b_radps(sigma3(core::layout::kGyroBias));
  const core::StateMask& active = engine.activeStates();
  auto modelled = [&active](const core::StateBlock& b) {
    return active[static_cast<std::size_t>(b.index)];
  };
  const core::ImuCorrection imu = engine.imuCorrection();
  sol.accel_scale_b(bus::toArray(imu.accel_scale_b));
  sol.gyro_scale_b(bus::toArray(imu.gyro_scale_b));
  sol.accel_scale_sigma_b(modelled(core::layout::kAccelScale) ? sigma3(core::layout::kAccelScale)
                                                              : std::array<double, 3>{});
  sol.gyro_scale_sigma_b(modelled(core::layout::kGyroScale) ? sigma3(core::layout::kGyroScale)
                                                            : std::array<double, 3>{});
  sol.clock_bias_m(engine.clockBias());
  sol.clock_drift_mps(engine.clockDrift());
  sol.clock_bias_sigma_m(
      std::sqrt(P(core::layout::kClockBias.index, core::layout::kClockBias.index)));
  sol.clock_drift_sigma_mps(
      std::sqrt(P(core::layout::kClockDrift.index, core::layout::kClockDrift.index)));
  sol.covariance_valid(engine.trustworthy());
  // Biases: estimated plus those compensated by command.
  sol.accel_bias_b_mps2(bus::toArray(engine.accelBias()));
  sol.gyro_bias_b_radps(bus::toArray(engine.gyroBias()));
  sol.mode(toIdl(engine.mode()));
  sol.fusion(toIdl(engine.fusion(), config.aiding));
  sol.active_fault_flags(pipeline_flags | faultFlags(engine.status()));
  sol.imu_samples_used(engine.counters().imu_used);
  sol.start_source(toIdl(config.start, engine.alignedStart().attitude_source));
  // Tightly coupled, the levels assume the fault manager's GLR acts; on fixes the engine's own
  // detector is the monitor.
  if (fault_monitor_alive || config.aiding != core::AidingMode::kTightlyCoupled) {
    const core::ProtectionLevels pl = engine.protectionLevels();
    sol.integrity(engine.trustworthy() ? toIdl(pl.state) : navbus::INTEGRITY_UNAVAILABLE);
    sol.horizontal_protection_level_m(pl.horizontal_m);
    sol.vertical_protection_level_m(pl.vertical_m);
  }
  return sol;
}

navbus::NavigationSolution lowLatencySolution(const navbus::NavigationSolution& anchor,
                                              const core::NavState& state, std::uint64_t seq) {
  navbus::NavigationSolution out = anchor;
  out.seq(seq);
  bus::fillSolution(state, out);
  out.output(navbus::OUTPUT_LOW_LATENCY);
  out.propagated_from_gps_ns(anchor.time_gps_ns());
  return out;
}

std::string describeAlignment(const core::NavigationEngine& engine) {
  static const char* const phases[] = {"waiting for a GNSS position", "waiting for rest",
                                       "levelled, waiting for the GNSS course", "aligned"};
  static const char* const attitude[] = {"none", "star tracker", "gyrocompassing", "GNSS course"};
  static const char* const position[] = {"none", "GNSS fix", "pseudoranges"};
  std::ostringstream out;
  out << "alignment: " << phases[static_cast<int>(engine.alignmentPhase())] << " after "
      << engine.counters().imu_aligning << " increments";
  if (engine.alignmentPhase() == core::AlignmentPhase::kAligned) {
    const core::AlignedStart& s = engine.alignedStart();
    out << " (attitude from " << attitude[static_cast<int>(s.attitude_source)] << ", position from "
        << position[static_cast<int>(s.position_source)] << "; 1-sigma tilt "
        << s.att_sigma_ned_rad.x() * 1e3 << " mrad, heading " << s.att_sigma_ned_rad.z() * 1e3
        << " mrad; gyrocompassing would reach " << s.gyrocompass_heading_sigma_rad * 1e3
        << " mrad)";
  }
  if (engine.alignmentFailedSolutions() > 0)
    out << ", pseudorange solutions failed " << engine.alignmentFailedSolutions();
  if (engine.counters().course_heading_checks > 0)
    out << ", heading measured again from the GNSS course "
        << engine.counters().course_heading_checks << " time(s)";
  return out.str();
}

std::uint32_t faultFlags(std::uint32_t engine_status) {
  std::uint32_t f = 0;
  if (engine_status & core::kStatusImuGap) f |= navbus::FAULT_IMU_GAP;
  if (engine_status & core::kStatusSatelliteExcluded) f |= navbus::FAULT_SATELLITE_EXCLUDED;
  if (engine_status & core::kStatusBiasCompensated) f |= navbus::FAULT_SENSOR_AXIS;
  if (engine_status & core::kStatusAxisFailed) f |= navbus::FAULT_IMU_AXIS_FAILED;
  if (engine_status & core::kStatusInconsistent) f |= navbus::FAULT_FILTER_INCONSISTENT;
  return f;
}

navbus::IntegrityState toIdl(core::IntegrityState s) {
  switch (s) {
    case core::IntegrityState::kNotMonitored:
      return navbus::INTEGRITY_NOT_MONITORED;
    case core::IntegrityState::kInitializing:
      return navbus::INTEGRITY_INITIALIZING;
    case core::IntegrityState::kAvailable:
      return navbus::INTEGRITY_AVAILABLE;
    case core::IntegrityState::kUnavailable:
      return navbus::INTEGRITY_UNAVAILABLE;
  }
  return navbus::INTEGRITY_NOT_MONITORED;
}

navbus::FilterMode toIdl(core::EngineMode mode) {
  switch (mode) {
    case core::EngineMode::kInitializing:
      return navbus::MODE_INITIALIZING;
    case core::EngineMode::kInertialOnly:
      return navbus::MODE_INERTIAL_ONLY;
    case core::EngineMode::kInertialLost:
      return navbus::MODE_INERTIAL_LOST;
    case core::EngineMode::kTightlyCoupled:
      return navbus::MODE_TIGHTLY_COUPLED;
    case core::EngineMode::kLooselyCoupled:
      return navbus::MODE_LOOSELY_COUPLED;
    case core::EngineMode::kMdfF1:
      return navbus::MODE_MDF_F1_ZUPT;
    case core::EngineMode::kMdfF2:
      return navbus::MODE_MDF_F2_GNSS;
    case core::EngineMode::kMdfF3:
      return navbus::MODE_MDF_F3_RECOVERY;
    case core::EngineMode::kMdfF4:
      return navbus::MODE_MDF_F4_CIF;
    case core::EngineMode::kAidedAxisFailed:
      return navbus::MODE_AIDED_AXIS_FAILED;
    case core::EngineMode::kAligning:
      return navbus::MODE_ALIGNING;
    case core::EngineMode::kReinitialising:
      return navbus::MODE_REINITIALISING;
  }
  return navbus::MODE_INITIALIZING;
}

navbus::StartSource toIdl(core::StartSource start, core::AttitudeSource attitude) {
  if (start == core::StartSource::kConfigured) return navbus::START_CONFIGURED;
  switch (attitude) {
    case core::AttitudeSource::kStarTracker:
      return navbus::START_STAR_TRACKER;
    case core::AttitudeSource::kGyrocompass:
      return navbus::START_GYROCOMPASS;
    case core::AttitudeSource::kGnssCourse:
      return navbus::START_GNSS_COURSE;
    case core::AttitudeSource::kNone:
      break;  // not aligned yet: no solution is published
  }
  return navbus::START_CONFIGURED;
}

navbus::FusionStructure toIdl(core::FusionStructure s, core::AidingMode aiding) {
  if (aiding == core::AidingMode::kInertialOnly) return navbus::FUSION_NONE;
  switch (s) {
    case core::FusionStructure::kCentralized:
      return navbus::FUSION_CENTRALIZED;
    case core::FusionStructure::kFederated:
      return navbus::FUSION_FEDERATED;
    case core::FusionStructure::kAdaptive:
      return navbus::FUSION_ADAPTIVE;
  }
  return navbus::FUSION_NONE;
}

navbus::MeasurementKind toIdl(core::NoiseStream s) {
  switch (s) {
    case core::NoiseStream::kFixPosition:
      return navbus::MEAS_POSITION;
    case core::NoiseStream::kFixVelocity:
      return navbus::MEAS_VELOCITY;
    case core::NoiseStream::kPseudorange:
      return navbus::MEAS_PSEUDORANGE;
    case core::NoiseStream::kPseudorangeRate:
      return navbus::MEAS_PSEUDORANGE_RATE;
    case core::NoiseStream::kZeroVelocity:
      return navbus::MEAS_ZERO_VELOCITY;
    case core::NoiseStream::kNonHolonomic:
      return navbus::MEAS_NONHOLONOMIC;
    case core::NoiseStream::kStarAttitude:
      return navbus::MEAS_ATTITUDE;
  }
  return navbus::MEAS_POSITION;
}

void appendNoiseScales(const core::NavigationEngine& engine, navbus::FilterDiagnostics& msg) {
  const core::EngineConfig& c = engine.config();
  msg.process_noise_scale(engine.processNoiseScale().scale());
  if (!c.adaptive_noise.enabled) return;
  for (int i = 0; i < core::kNoiseStreams; ++i) {
    if (!c.adaptive_noise_streams[static_cast<std::size_t>(i)]) continue;
    const auto s = static_cast<core::NoiseStream>(i);
    navbus::NoiseScale n;
    n.stream(toIdl(s));
    n.scale(engine.noiseScale(s).scale());
    msg.noise_scales().push_back(n);
  }
}

}  // namespace navbus::nav_filter
