#include "navbus/evaluation/imu_noise_survey.hpp"

#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#include <navbus_idl/Imu.h>

#include "navbus/bus/config.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/core/math/allan.hpp"
#include "navbus/core/math/units.hpp"
#include "navbus/records/csv_messages.hpp"
#include "navbus/records/recording_layout.hpp"

namespace navbus::evaluation {

namespace {

std::vector<navbus::ImuIncrement> recordedIncrements(const std::filesystem::path& dir) {
  std::vector<navbus::ImuIncrement> out;
  const auto blocks = dir / records::recordFileName(bus::topic::kImuIncrementBlock);
  const auto singles = dir / records::recordFileName(bus::topic::kImuIncrement);
  if (std::filesystem::exists(blocks)) {
    const records::CsvTable t = records::readCsv(blocks);
    for (const auto& b :
         records::parseMessages<navbus::ImuIncrementBlock>(t, records::messageRowRanges(t)))
      out.insert(out.end(), b.increments().begin(), b.increments().end());
  } else if (std::filesystem::exists(singles)) {
    const records::CsvTable t = records::readCsv(singles);
    out = records::parseMessages<navbus::ImuIncrement>(t, records::messageRowRanges(t));
  } else {
    throw bus::ConfigError(dir.string() +
                           ": no navbus_imu_increment_block.csv or "
                           "navbus_imu_increment.csv");
  }
  return out;
}

double rms3(const std::array<double, 6>& v, int first) {
  return std::sqrt(
      (v[first] * v[first] + v[first + 1] * v[first + 1] + v[first + 2] * v[first + 2]) / 3.0);
}

}  // namespace

ImuNoiseSurvey surveyImuNoise(const std::string& recording_dir, double from_s, double to_s) {
  const std::vector<navbus::ImuIncrement> all = recordedIncrements(recording_dir);
  if (all.empty()) throw bus::ConfigError(recording_dir + ": no IMU increments");
  ImuNoiseSurvey s;
  s.from_s = from_s;
  s.to_s = to_s;
  const auto t0 = static_cast<std::int64_t>(all.front().time_gps_ns());
  std::array<std::vector<double>, 6> rates;
  double interval_sum = 0.0;
  for (const auto& inc : all) {
    const double t = 1e-9 * static_cast<double>(static_cast<std::int64_t>(inc.time_gps_ns()) - t0);
    if (t < from_s || t > to_s) continue;
    const double dt = 1e-9 * static_cast<double>(inc.interval_ns());
    interval_sum += dt;
    for (int a = 0; a < 3; ++a) {
      rates[a].push_back(inc.delta_vel_b_mps()[a] / dt);
      rates[3 + a].push_back(inc.delta_angle_b_rad()[a] / dt);
    }
  }
  s.increments = rates[0].size();
  if (interval_sum < 3.0)
    throw bus::ConfigError(
        fmt::format("{}: {:.2f} s of increments between {} s and {} s; the "
                    "survey needs at least 3 s",
                    recording_dir, interval_sum, from_s, to_s));
  s.period_s = interval_sum / static_cast<double>(s.increments);
  s.flicker_floor.fill(INFINITY);
  for (double tau = s.period_s; tau <= interval_sum / 3.0; tau *= 2.0) {
    const auto m = static_cast<std::size_t>(std::llround(tau / s.period_s));
    AllanPoint p;
    p.tau_s = static_cast<double>(m) * s.period_s;
    for (int a = 0; a < 6; ++a) {
      p.deviation[a] = core::allanDeviation(rates[a], s.period_s, m);
      s.flicker_floor[a] = std::min(s.flicker_floor[a], p.deviation[a]);
    }
    s.curve.push_back(p);
  }
  const auto one_second = static_cast<std::size_t>(std::llround(1.0 / s.period_s));
  for (int a = 0; a < 6; ++a)
    s.white_noise[a] = core::allanDeviation(rates[a], s.period_s, one_second);
  return s;
}

std::string formatSurvey(const ImuNoiseSurvey& s) {
  std::string out = fmt::format(
      "{} increments from {} s to {} s, mean interval {:.4f} s\n"
      "tau [s]   accel x y z [m/s^2]                gyro x y z [deg/s]\n",
      s.increments, s.from_s, s.to_s, s.period_s);
  for (const AllanPoint& p : s.curve) {
    out +=
        fmt::format("{:7.3f}   {:10.3e} {:10.3e} {:10.3e}   {:10.3e} {:10.3e} {:10.3e}\n", p.tau_s,
                    p.deviation[0], p.deviation[1], p.deviation[2], p.deviation[3] / units::kDeg,
                    p.deviation[4] / units::kDeg, p.deviation[5] / units::kDeg);
  }
  const double accel = rms3(s.white_noise, 0);
  const double gyro = rms3(s.white_noise, 3);
  out += fmt::format(
      "white noise (sigma_A at 1 s, RMS of the axes): accel {:.3e} m/s^2/sqrt(Hz), gyro "
      "{:.3e} deg/s/sqrt(Hz)\nsmallest sigma_A (flicker floor, RMS of the axes): accel {:.3e} "
      "m/s^2, gyro {:.3e} deg/s\nekf:\n  accel_noise_ug_per_sqrthz: {:.0f}\n"
      "  gyro_arw_deg_per_sqrth: {:.3g}\n",
      accel, gyro / units::kDeg, rms3(s.flicker_floor, 0), rms3(s.flicker_floor, 3) / units::kDeg,
      accel / units::kMicroG, gyro / units::kDeg * 60.0);
  return out;
}

MotionNoise motionNoise(const ImuNoiseSurvey& rest, const ImuNoiseSurvey& motion) {
  const AllanPoint& r = rest.curve.front();
  const AllanPoint& m = motion.curve.front();
  if (std::abs(r.tau_s - m.tau_s) > 0.01 * r.tau_s)
    throw bus::ConfigError(fmt::format(
        "the stretch in motion is sampled every {:.4f} s, the one at rest every {:.4f} s: their "
        "one-sample Allan deviations do not compare",
        m.tau_s, r.tau_s));
  MotionNoise n;
  n.accel_one_sample_rest = rms3(r.deviation, 0);
  n.accel_one_sample_motion = rms3(m.deviation, 0);
  n.gyro_one_sample_rest = rms3(r.deviation, 3);
  n.gyro_one_sample_motion = rms3(m.deviation, 3);
  n.accel_ratio = n.accel_one_sample_motion / n.accel_one_sample_rest;
  n.gyro_ratio = n.gyro_one_sample_motion / n.gyro_one_sample_rest;
  n.accel_density = n.accel_ratio * rms3(rest.white_noise, 0);
  n.gyro_density = n.gyro_ratio * rms3(rest.white_noise, 3);
  return n;
}

std::string formatMotionNoise(const ImuNoiseSurvey& motion, const MotionNoise& n) {
  return fmt::format(
      "in motion from {} s to {} s ({} increments): sigma_A at one sample ({:.3f} s), RMS of the "
      "axes: accel {:.3e} m/s^2 ({:.3e} at rest, {:.2f} times), gyro {:.3e} deg/s ({:.3e} at "
      "rest, {:.2f} times)\nwhite noise in motion (the 1-s densities at rest times those "
      "ratios): accel {:.3e} m/s^2/sqrt(Hz), gyro {:.3e} deg/s/sqrt(Hz)\nekf (in motion):\n"
      "  accel_noise_ug_per_sqrthz: {:.0f}\n  gyro_arw_deg_per_sqrth: {:.3g}\n",
      motion.from_s, motion.to_s, motion.increments, motion.curve.front().tau_s,
      n.accel_one_sample_motion, n.accel_one_sample_rest, n.accel_ratio,
      n.gyro_one_sample_motion / units::kDeg, n.gyro_one_sample_rest / units::kDeg, n.gyro_ratio,
      n.accel_density, n.gyro_density / units::kDeg, n.accel_density / units::kMicroG,
      n.gyro_density / units::kDeg * 60.0);
}

}  // namespace navbus::evaluation
