// `navbus allan`: the noise densities of a recorded IMU from the overlapping Allan deviation
// (IEEE Std 952) of a stretch at rest, in the units of the filter configuration's ekf keys.
// White noise N gives sigma_A(tau) = N / sqrt(tau): N is read at tau = 1 s.
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

}  // namespace navbus::evaluation
