#include "navbus/core/filter/multi_dimensional.hpp"

#include <cmath>

namespace navbus::core {

using namespace layout;

StateMask stageMask(MdfStage stage) {
  switch (stage) {
    case MdfStage::kF1ZeroVelocity: {
      StateMask m = maskOf({kVel});
      m.set(static_cast<std::size_t>(kAtt.index));            // phi_N
      m.set(static_cast<std::size_t>(kAtt.index + 1));        // phi_E
      m.set(static_cast<std::size_t>(kAccelBias.index + 2));  // bias_z
      m.set(static_cast<std::size_t>(kGyroBias.index));       // eps_x
      m.set(static_cast<std::size_t>(kGyroBias.index + 1));   // eps_y
      return m;
    }
    case MdfStage::kF2Gnss:
      return maskOf({kPos, kVel, kAtt, kAccelBias, kGyroBias});
    case MdfStage::kF3Recovery:
      return maskOf({kPos, kVel, kAtt});
    case MdfStage::kF4Constraint:
      return maskOf({kVel, kAtt, kAccelBias, kGyroBias});
  }
  return StateMask();
}

void StationarityDetector::configure(const StationarityConfig& c, double imu_period_s) {
  config_ = c;
  const long n = std::lround(c.window_s / imu_period_s);
  length_ = static_cast<int>(n < 2 ? 2 : (n > kMaxWindow ? kMaxWindow : n));
  count_ = 0;
  next_ = 0;
  stationary_ = false;
}

bool StationarityDetector::update(const ImuIncrement& inc, double speed_mps) {
  Eigen::Matrix<double, 6, 1> s;
  s << inc.delta_vel_b_mps / inc.interval_s, inc.delta_angle_b_rad / inc.interval_s;
  samples_[static_cast<std::size_t>(next_)] = s;
  next_ = (next_ + 1) % length_;
  if (count_ < length_) ++count_;
  if (count_ < length_) {
    stationary_ = false;
    return stationary_;
  }
  Eigen::Matrix<double, 6, 1> mean = Eigen::Matrix<double, 6, 1>::Zero();
  for (int i = 0; i < length_; ++i) mean += samples_[static_cast<std::size_t>(i)];
  mean /= length_;
  Eigen::Matrix<double, 6, 1> var = Eigen::Matrix<double, 6, 1>::Zero();
  for (int i = 0; i < length_; ++i) {
    var += (samples_[static_cast<std::size_t>(i)] - mean).array().square().matrix();
  }
  var /= (length_ - 1);
  const double accel_std = std::sqrt(var.head<3>().sum() / 3.0);
  const double gyro_std = std::sqrt(var.tail<3>().sum() / 3.0);
  stationary_ = accel_std < config_.accel_std_mps2 && gyro_std < config_.gyro_std_radps &&
                speed_mps < config_.speed_mps;
  return stationary_;
}

StageDecision StageSelector::update(bool stationary, bool gnss_available, std::int64_t t_ns) {
  MdfStage next = stage_;
  if (stationary) {
    next = MdfStage::kF1ZeroVelocity;
  } else if (!gnss_available) {
    next = MdfStage::kF4Constraint;
  } else if (stage_ == MdfStage::kF4Constraint) {
    next = MdfStage::kF3Recovery;
  } else if (stage_ == MdfStage::kF3Recovery) {
    const double in_recovery_s = 1e-9 * static_cast<double>(t_ns - recovery_start_ns_);
    next = in_recovery_s >= config_.recovery_s ? MdfStage::kF2Gnss : MdfStage::kF3Recovery;
  } else {
    next = MdfStage::kF2Gnss;
  }
  if (!started_) {
    started_ = true;
    stage_ = next;
    if (next == MdfStage::kF3Recovery) recovery_start_ns_ = t_ns;
    return {stage_, CovarianceReset::kNone, true};
  }
  if (next == stage_) return {stage_, CovarianceReset::kNone, false};
  CovarianceReset reset = CovarianceReset::kFs;
  const bool multi = config_.policy == MdfPolicy::kMultiDimensional;
  if (stage_ == MdfStage::kF1ZeroVelocity) {
    reset = multi ? CovarianceReset::kFsA : CovarianceReset::kNone;
  } else if (next == MdfStage::kF3Recovery) {
    recovery_start_ns_ = t_ns;
    reset = multi ? CovarianceReset::kFsI
                  : (config_.policy == MdfPolicy::kResetAll ? CovarianceReset::kAll
                                                            : CovarianceReset::kNone);
  } else if (!multi) {
    reset = CovarianceReset::kNone;
  }
  stage_ = next;
  return {stage_, reset, true};
}

}  // namespace navbus::core
