// `navbus allan`: the noise densities of a recorded IMU from the overlapping Allan deviation
// (IEEE Std 952) of a stretch at rest, in the units of the filter configuration's ekf keys.
// White noise N gives sigma_A(tau) = N / sqrt(tau): N is read at tau = 1 s. In motion the
// vehicle's own accelerations and turns dominate sigma_A from a few samples on, but not at one
// sample (0.01 s at 100 Hz), where the vibration does: the densities in motion are the ones at
// rest scaled by how much larger sigma_A at one sample is in motion than at rest.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace navbus::evaluation {

struct AllanPoint {
  double tau_s{0.0};
  std::array<double, 6> deviation{};  ///< accel x y z [m/s^2], gyro x y z [rad/s], IMU axes
};

struct ImuNoiseSurvey {
  double from_s{0.0}, to_s{0.0};  ///< the stretch, seconds after the first increment
  std::size_t increments{0};
  double period_s{0.0};  ///< mean interval
  std::vector<AllanPoint> curve;
  std::array<double, 6> white_noise{};    ///< sigma_A(1 s): [m/s^2/sqrt(Hz)], [rad/s/sqrt(Hz)]
  std::array<double, 6> flicker_floor{};  ///< the smallest sigma_A of the curve
};

/// Reads the recording's IMU (navbus_imu_increment_block.csv or navbus_imu_increment.csv);
/// throws bus::ConfigError when the stretch holds under 3 s of increments.
ImuNoiseSurvey surveyImuNoise(const std::string& recording_dir, double from_s, double to_s);

/// The survey as text, ending with the two ekf keys (RMS over the three axes).
std::string formatSurvey(const ImuNoiseSurvey& s);

/// The vibration in motion against the stretch at rest: sigma_A at one sample (RMS of the
/// axes) in each, their ratio, and the rest's 1-s white noise scaled by it.
struct MotionNoise {
  double accel_one_sample_rest{0.0}, accel_one_sample_motion{0.0};  ///< [m/s^2]
  double gyro_one_sample_rest{0.0}, gyro_one_sample_motion{0.0};    ///< [rad/s]
  double accel_ratio{0.0}, gyro_ratio{0.0};
  double accel_density{0.0};  ///< [m/s^2/sqrt(Hz)]
  double gyro_density{0.0};   ///< [rad/s/sqrt(Hz)]
};

/// Throws bus::ConfigError when the two stretches were not sampled alike (one-sample tau
/// differing by more than 1 %).
MotionNoise motionNoise(const ImuNoiseSurvey& rest, const ImuNoiseSurvey& motion);

/// The comparison as text, ending with the two ekf keys in motion.
std::string formatMotionNoise(const ImuNoiseSurvey& motion, const MotionNoise& n);

}  // namespace navbus::evaluation
