#include "navbus/sim/faults.hpp"

#include <algorithm>
#include <cmath>

namespace navbus::sim {

Eigen::Vector3d FaultSchedule::imuBias(double t, SensorKind sensor, int unit) const {
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const auto& f : faults_) {
    if (f.sensor != sensor || f.unit != unit || !active(f, t)) continue;
    if (f.kind == FaultKind::kImuBiasStep) b[f.axis] += f.magnitude;
    if (f.kind == FaultKind::kImuBiasRamp) {
      const double ramp = f.slope * (t - f.start_s);
      b[f.axis] += f.saturation > 0.0 ? std::clamp(ramp, -f.saturation, f.saturation) : ramp;
    }
  }
  return b;
}

Eigen::Vector3d FaultSchedule::scaleError(double t, SensorKind sensor, int unit) const {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (const auto& f : faults_) {
    if (f.kind == FaultKind::kImuScaleFactorStep && f.sensor == sensor && f.unit == unit &&
        active(f, t))
      s[f.axis] += f.magnitude;
  }
  return s;
}

Eigen::Vector3d FaultSchedule::noiseFactor(double t, SensorKind sensor, int unit) const {
  Eigen::Vector3d k = Eigen::Vector3d::Ones();
  for (const auto& f : faults_) {
    if (f.kind == FaultKind::kImuNoiseIncrease && f.sensor == sensor && f.unit == unit &&
        active(f, t))
      k[f.axis] *= f.magnitude;
  }
  return k;
}

std::optional<double> FaultSchedule::stuckSince(SensorKind sensor, int axis, double t,
                                                int unit) const {
  for (const auto& f : faults_) {
    if (f.kind == FaultKind::kSensorStuck && f.sensor == sensor && f.axis == axis &&
        f.unit == unit && active(f, t))
      return f.start_s;
  }
  return std::nullopt;
}

double FaultSchedule::pseudorangeError(int sv_id, double t, int receiver) const {
  double e = 0.0;
  for (const auto& f : faults_) {
    if (f.receiver != receiver || !active(f, t)) continue;
    if (f.kind == FaultKind::kReceiverClockJump) e += f.magnitude;
    if (f.sv_id != sv_id) continue;
    if (f.kind == FaultKind::kPseudorangeStep) e += f.magnitude;
    if (f.kind == FaultKind::kGnssMultipath)
      e += f.magnitude * std::sin(2.0 * M_PI * (t - f.start_s) / f.period_s);
    if (f.kind != FaultKind::kPseudorangeRamp) continue;
    const double ramp = f.slope * (t - f.start_s);
    // Saturation keeps the sign of the slope (seed 000: 12.5 m/s saturating at 125 m after 10 s).
    e += f.saturation > 0.0 ? std::copysign(std::min(std::abs(ramp), f.saturation), ramp) : ramp;
  }
  return e;
}

Eigen::Vector3d FaultSchedule::positionPulse(double t) const {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (const auto& f : faults_) {
    if (f.kind == FaultKind::kGnssPositionPulse && active(f, t)) p += f.vector;
  }
  return p;
}

Eigen::Vector3d FaultSchedule::starTrackerBias(double t) const {
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const auto& f : faults_) {
    if (f.kind == FaultKind::kStarTrackerBias && active(f, t)) b += f.vector;
  }
  return b;
}

bool FaultSchedule::any(FaultKind kind, double t) const {
  return std::any_of(faults_.begin(), faults_.end(),
                     [&](const Fault& f) { return f.kind == kind && active(f, t); });
}

bool FaultSchedule::gnssOut(double t) const {
  return std::any_of(faults_.begin(), faults_.end(), [&](const Fault& f) {
    return f.kind == FaultKind::kGnssOutage && f.receiver < 0 && active(f, t);
  });
}

bool FaultSchedule::receiverOut(double t, int receiver) const {
  return std::any_of(faults_.begin(), faults_.end(), [&](const Fault& f) {
    return f.kind == FaultKind::kGnssOutage && (f.receiver < 0 || f.receiver == receiver) &&
           active(f, t);
  });
}

const char* faultKindName(FaultKind kind) {
  switch (kind) {
    case FaultKind::kImuBiasStep:
      return "imu_bias_step";
    case FaultKind::kImuBiasRamp:
      return "imu_bias_ramp";
    case FaultKind::kPseudorangeRamp:
      return "pseudorange_ramp";
    case FaultKind::kGnssPositionPulse:
      return "gnss_position_pulse";
    case FaultKind::kSensorStuck:
      return "sensor_stuck";
    case FaultKind::kGnssOutage:
      return "gnss_outage";
    case FaultKind::kStarTrackerOutage:
      return "star_tracker_outage";
    case FaultKind::kPseudorangeStep:
      return "pseudorange_step";
    case FaultKind::kReceiverClockJump:
      return "receiver_clock_jump";
    case FaultKind::kImuScaleFactorStep:
      return "imu_scale_factor_step";
    case FaultKind::kImuNoiseIncrease:
      return "imu_noise_increase";
    case FaultKind::kGnssMultipath:
      return "gnss_multipath";
    case FaultKind::kStarTrackerBias:
      return "star_tracker_bias";
  }
  return "unknown";
}

}  // namespace navbus::sim
