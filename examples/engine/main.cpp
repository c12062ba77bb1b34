// navbus::core alone: integrate 10 s of a perfect stationary, levelled, north-pointing IMU at
// 200 Hz with the strapdown mechanization and print how far the solution drifted (it should
// stay within millimetres: the increments are exactly what the Earth model predicts).
#include <cmath>
#include <cstdio>

#include <navbus/core/ins/strapdown.hpp>
#include <navbus/core/math/earth.hpp>

namespace earth = navbus::core::earth;

int main() {
  constexpr double kDegToRad = M_PI / 180.0;
  constexpr double kRate_hz = 200.0;
  constexpr double kDuration_s = 10.0;
  constexpr std::int64_t kInterval_ns = static_cast<std::int64_t>(1e9 / kRate_hz);
  const double interval_s = 1.0 / kRate_hz;

  navbus::core::NavState start;
  start.position.latitude_rad = 45.0 * kDegToRad;
  start.position.longitude_rad = 7.0 * kDegToRad;
  start.position.height_m = 300.0;

  // Body = NED: the accelerometers read minus gravity, the gyros the Earth's rotation.
  const Eigen::Vector3d gravity_ned_mps2 =
      earth::gravityNed(start.position.latitude_rad, start.position.height_m);
  const double lat = start.position.latitude_rad;
  const Eigen::Vector3d earth_rate_ned_radps(earth::kRotationRate_radps * std::cos(lat), 0.0,
                                             -earth::kRotationRate_radps * std::sin(lat));

  navbus::core::StrapdownNed strapdown;
  strapdown.initialize(start);
  const int steps = static_cast<int>(kDuration_s * kRate_hz);
  for (int k = 1; k <= steps; ++k) {
    navbus::core::ImuIncrement inc;
    inc.time_ns = k * kInterval_ns;
    inc.interval_s = interval_s;
    inc.delta_vel_b_mps = -gravity_ned_mps2 * interval_s;
    inc.delta_angle_b_rad = earth_rate_ned_radps * interval_s;
    strapdown.propagate(inc);
  }
  const navbus::core::NavState& end = strapdown.state();
  const Eigen::Vector3d drift_ned_m = earth::differenceNed(end.position, start.position);
  std::printf("%d increments integrated over %.1f s\n", steps, kDuration_s);
  std::printf("position drift N E D: %.3g %.3g %.3g m\n", drift_ned_m.x(), drift_ned_m.y(),
              drift_ned_m.z());
  std::printf("velocity N E D: %.3g %.3g %.3g m/s\n", end.vel_ned_mps.x(), end.vel_ned_mps.y(),
              end.vel_ned_mps.z());
  // A wrong sign or frame anywhere shows as metres of drift in 10 s.
  return drift_ned_m.norm() < 0.05 ? 0 : 1;
}
