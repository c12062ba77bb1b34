#include "sim_config.hpp"

#include <cmath>

#include "navbus/bus/config.hpp"

namespace navbus::sensor_sim {

namespace {
constexpr double kDeg = M_PI / 180.0;
constexpr double kMicroG = 9.80665e-6;  // m/s^2
constexpr double kDegPerHour = kDeg / 3600.0;

/// Integer number of `fast` periods in one `slow` period, or a ConfigError.
int ratio(double fast_hz, double slow_hz, const std::string& name) {
  const double r = fast_hz / slow_hz;
  if (std::abs(r - std::round(r)) > 1e-9 || r < 1.0) {
    throw bus::ConfigError("configuration " + name + " = " + std::to_string(slow_hz) +
                           " Hz must divide the IMU rate " + std::to_string(fast_hz) + " Hz");
  }
  return static_cast<int>(std::lround(r));
}
}  // namespace

SimConfig parseSimConfig(const YAML::Node& root) {
  SimConfig c;
  auto& s = c.source;
  const YAML::Node veh = root["vehicle"];
  const core::earth::Geodetic default_site{36.5 * kDeg, 127.5 * kDeg, 100.0};  // seed 000
  s.position = bus::getGeodeticDeg(veh, "vehicle", &default_site);
  s.roll_pitch_yaw_rad = bus::getRollPitchYawDeg(veh, "vehicle");

  const YAML::Node timing = root["timing"];
  const std::string start = bus::get<std::string>(timing, "timing", "start", "now");
  if (start == "now") {
    c.start_now = true;
  } else {
    c.start_now = false;
    try {
      s.start_time_ns = static_cast<std::int64_t>(std::stoull(start));
    } catch (const std::exception&) {
      throw bus::ConfigError("configuration timing.start = '" + start +
                             "' is neither 'now' nor GPS nanoseconds");
    }
  }
  c.duration_s = bus::checkRange(bus::get<double>(timing, "timing", "duration_s", 0.0), 0, 1e7,
                                 "timing.duration_s");
  const std::string pacing = bus::get<std::string>(timing, "timing", "pacing", "realtime");
  if (pacing == "realtime") {
    c.pacing = Pacing::kRealTime;
  } else if (pacing == "fast") {
    c.pacing = Pacing::kFast;
  } else {
    throw bus::ConfigError("configuration timing.pacing = '" + pacing +
                           "' is not realtime or fast");
  }
  c.wait_for_readers_s =
      bus::checkRange(bus::get<double>(timing, "timing", "wait_for_readers_s", 10.0), 0, 3600,
                      "timing.wait_for_readers_s");
  const YAML::Node wait = timing["min_readers"];
  auto readers = [&](const char* key, int fallback) {
    return static_cast<int>(
        bus::checkRange(bus::get<int>(wait, "timing.min_readers", key, fallback), 0, 64,
                        std::string("timing.min_readers.") + key));
  };
  c.min_readers.imu = readers("imu", 1);
  c.min_readers.raw_imu = readers("raw_imu", 0);
  c.min_readers.gnss = readers("gnss", 1);
  c.min_readers.star_tracker = readers("star_tracker", 1);
  const double imu_hz = bus::checkRange(bus::get<double>(timing, "timing", "imu_rate_hz", 100.0), 1,
                                        2000, "timing.imu_rate_hz");
  const double period_ns = 1e9 / imu_hz;
  if (std::abs(period_ns - std::round(period_ns)) > 1e-6) {
    throw bus::ConfigError("configuration timing.imu_rate_hz = " + std::to_string(imu_hz) +
                           " does not give an integer period in nanoseconds");
  }
  s.imu_period_ns = std::llround(period_ns);
  const double raw_hz = bus::checkRange(bus::get<double>(timing, "timing", "raw_rate_hz", 2400.0),
                                        1, 10000, "timing.raw_rate_hz");
  s.raw_samples_per_increment =
      ratio(raw_hz, imu_hz, "timing.imu_rate_hz (raw_rate_hz / imu_rate_hz)");
  if (s.raw_samples_per_increment > 256) {
    throw bus::ConfigError("configuration timing.raw_rate_hz / imu_rate_hz = " +
                           std::to_string(s.raw_samples_per_increment) +
                           " exceeds 256 samples per block");
  }
  const double gnss_hz = bus::checkRange(bus::get<double>(timing, "timing", "gnss_rate_hz", 1.0),
                                         0.01, 100, "timing.gnss_rate_hz");
  s.gnss_every_n_increments = ratio(imu_hz, gnss_hz, "timing.gnss_rate_hz");
  const double st_hz =
      bus::checkRange(bus::get<double>(timing, "timing", "star_tracker_rate_hz", 5.0), 0.01, 100,
                      "timing.star_tracker_rate_hz");
  s.star_tracker_every_n_increments = ratio(imu_hz, st_hz, "timing.star_tracker_rate_hz");

  const YAML::Node imu = root["imu"];
  s.imu.accel_bias_b_mps2 = bus::getVector3(imu, "imu", "accel_bias_ug", kMicroG);
  s.imu.gyro_bias_b_radps = bus::getVector3(imu, "imu", "gyro_bias_deg_per_h", kDegPerHour);
  // ug/sqrt(Hz) -> (m/s^2)/sqrt(Hz); deg/sqrt(h) -> rad/sqrt(s) = (rad/s)/sqrt(Hz).
  s.imu.accel_noise_density_mps2_per_sqrthz =
      bus::checkRange(bus::get<double>(imu, "imu", "accel_noise_ug_per_sqrthz", 0.0), 0, 1e5,
                      "imu.accel_noise_ug_per_sqrthz") *
      kMicroG;
  s.imu.gyro_noise_density_radps_per_sqrthz =
      bus::checkRange(bus::get<double>(imu, "imu", "gyro_arw_deg_per_sqrth", 0.0), 0, 100,
                      "imu.gyro_arw_deg_per_sqrth") *
      kDeg / 60.0;

  const YAML::Node gnss = root["gnss"];
  s.gnss.elevation_mask_rad =
      bus::checkRange(bus::get<double>(gnss, "gnss", "elevation_mask_deg", 5.0), -10, 60,
                      "gnss.elevation_mask_deg") *
      kDeg;
  s.gnss.max_satellites = static_cast<int>(bus::checkRange(
      bus::get<int>(gnss, "gnss", "max_satellites", 12), 1, 32, "gnss.max_satellites"));
  s.gnss.clock_bias_m = bus::get<double>(gnss, "gnss", "clock_bias_m", 3000.0);
  s.gnss.clock_drift_mps = bus::get<double>(gnss, "gnss", "clock_drift_mps", 1.0);
  s.gnss.pseudorange_sigma_m =
      bus::checkRange(bus::get<double>(gnss, "gnss", "pseudorange_sigma_m", 3.0), 1e-3, 1e3,
                      "gnss.pseudorange_sigma_m");
  s.gnss.pseudorange_rate_sigma_mps =
      bus::checkRange(bus::get<double>(gnss, "gnss", "pseudorange_rate_sigma_mps", 0.05), 1e-4, 100,
                      "gnss.pseudorange_rate_sigma_mps");
  s.gnss.fix_pos_sigma_m =
      bus::checkRange(bus::get<double>(gnss, "gnss", "fix_position_sigma_m", 2.5), 1e-3, 1e3,
                      "gnss.fix_position_sigma_m");
  s.gnss.fix_vel_sigma_mps =
      bus::checkRange(bus::get<double>(gnss, "gnss", "fix_velocity_sigma_mps", 0.1), 1e-4, 100,
                      "gnss.fix_velocity_sigma_mps");

  const YAML::Node st = root["star_tracker"];
  s.star_tracker_sigma_rad =
      bus::checkRange(bus::get<double>(st, "star_tracker", "sigma_arcsec", 0.3), 1e-3, 3600,
                      "star_tracker.sigma_arcsec") *
      kDeg / 3600.0;

  const YAML::Node ids = root["ids"];
  c.imu_sensor_id = bus::get<std::uint32_t>(ids, "ids", "imu", 1);
  c.gnss_receiver_id = bus::get<std::uint32_t>(ids, "ids", "gnss_receiver", 1);
  c.star_tracker_id = bus::get<std::uint32_t>(ids, "ids", "star_tracker", 1);
  const YAML::Node pub = root["publish"];
  c.publish_raw = bus::get<bool>(pub, "publish", "raw_imu", true);
  c.publish_gnss = bus::get<bool>(pub, "publish", "gnss", true);
  c.publish_star_tracker = bus::get<bool>(pub, "publish", "star_tracker", true);
  s.seed = bus::get<std::uint64_t>(root, "", "seed", 1);
  return c;
}

}  // namespace navbus::sensor_sim
