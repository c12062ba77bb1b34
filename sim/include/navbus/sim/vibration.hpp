// Vehicle vibration seen by an isolated IMU (seed 003's vehicle test): zero-mean random specific
// force and angular rate, white noise through a second-order Butterworth high-pass (an
// oscillation has no DC content: the IMU's displacement on its mount stays bounded and nothing
// random-walks) and the isolator, a second-order Butterworth low-pass (-40 dB per decade above
// its corner: a 40 Hz corner attenuates the 373-441 Hz dither band by about 40 dB, inside the
// 30-50 dB the paper reports). Active while the vehicle moves faster
// than `moving_speed_mps`. The vibration is an oscillation of the IMU on its mount: it is in
// the raw samples and in the increments (their sums), not in the truth trajectory (its
// displacement is millimetres).
#pragma once

#include <array>
#include <cstdint>
#include <random>

#include <Eigen/Core>

namespace navbus::sim {

struct VibrationSpec {
  bool enabled{false};
  double accel_rms_mps2{0.5};       ///< RMS specific force per axis at the IMU
  double gyro_rms_radps{0.01};      ///< RMS angular rate per axis at the IMU
  double isolator_corner_hz{40.0};  ///< -3 dB corner of the isolator low-pass
  double low_corner_hz{5.0};        ///< -3 dB corner of the high-pass (slowest vibration)
  double moving_speed_mps{0.5};     ///< vibrates above this ground speed
};

class VehicleVibration {
 public:
  VehicleVibration(const VibrationSpec& spec, double sample_rate_hz, std::uint64_t seed);
  /// Next sample: {specific force [m/s^2], angular rate [rad/s]} in the body frame; zeros while
  /// still (the filters keep running so the vibration starts smoothly).
  std::pair<Eigen::Vector3d, Eigen::Vector3d> next(double speed_mps);

 private:
  struct Coefficients {
    double b0{0}, b1{0}, b2{0}, a1{0}, a2{0};
  };
  struct Biquad {
    double z1{0.0}, z2{0.0};
  };
  static Coefficients butterworth(double corner_hz, double rate_hz, bool high_pass);
  static double step(const Coefficients& c, Biquad& s, double x);
  /// The band-pass: high-pass then low-pass.
  double filter(std::array<Biquad, 2>& s, double x) const;

  VibrationSpec spec_;
  Coefficients low_pass_, high_pass_;
  double input_sigma_accel_{0}, input_sigma_gyro_{0};
  std::array<std::array<Biquad, 2>, 6> state_{};
  std::mt19937_64 rng_;
  std::normal_distribution<double> unit_{0.0, 1.0};
};

}  // namespace navbus::sim
