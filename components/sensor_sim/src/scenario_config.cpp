#include "navbus/sensor_sim/scenario_config.hpp"

#include <cmath>

#include "navbus/bus/config.hpp"
#include "navbus/core/math/units.hpp"

namespace navbus::sensor_sim {

namespace {
using units::kArcsec;
using units::kDeg;
using units::kDegPerHour;
using units::kMicroG;
constexpr double kG = units::kStandardGravity;
using bus::checkKeys;
using bus::checkRange;
using bus::ConfigError;
using bus::get;

/// Integer number of `fast` periods in one `slow` period, or a ConfigError.
int ratio(double fast_hz, double slow_hz, const std::string& name) {
  const double r = fast_hz / slow_hz;
  if (std::abs(r - std::round(r)) > 1e-9 || r < 1.0) {
    throw ConfigError("configuration " + name + " = " + std::to_string(slow_hz) +
                      " Hz must divide " + std::to_string(fast_hz) + " Hz");
  }
  return static_cast<int>(std::lround(r));
}

/// node[key], or an undefined node when `node` itself is absent (yaml-cpp throws on indexing
/// an absent node).
YAML::Node child(const YAML::Node& node, const char* key) {
  return node ? node[key] : YAML::Node();
}

int axisIndex(const YAML::Node& n, const std::string& where) {
  const std::string a = get<std::string>(n, where, "axis", "x");
  if (a == "x") return 0;
  if (a == "y") return 1;
  if (a == "z") return 2;
  throw ConfigError("configuration " + where + ".axis = '" + a + "' is not x, y or z");
}

sim::SensorKind sensorKind(const YAML::Node& n, const std::string& where) {
  const std::string s = get<std::string>(n, where, "sensor", "accelerometer");
  if (s == "accelerometer") return sim::SensorKind::kAccelerometer;
  if (s == "gyro") return sim::SensorKind::kGyro;
  throw ConfigError("configuration " + where + ".sensor = '" + s +
                    "' is not accelerometer or gyro");
}

std::vector<sim::Segment> parseSegments(const YAML::Node& list) {
  std::vector<sim::Segment> out;
  if (!list || list.IsNull()) return out;
  if (!list.IsSequence()) throw ConfigError("configuration vehicle.segments must be a list");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node n = list[i];
    const std::string where = "vehicle.segments[" + std::to_string(i) + "]";
    const std::string type = bus::require<std::string>(n, where, "type");
    if (type == "accelerate") checkKeys(n, where, {"type", "duration_s", "accel_mps2"});
    if (type == "turn") checkKeys(n, where, {"type", "duration_s", "turn_rate_dps"});
    if (type == "climb") checkKeys(n, where, {"type", "duration_s", "climb_rate_dps"});
    if (type == "coordinated_turn")
      checkKeys(n, where, {"type", "duration_s", "turn_rate_dps", "speed_mps", "roll_time_s"});
    if (type == "attitude")
      checkKeys(n, where,
                {"type", "duration_s", "roll_rate_dps", "pitch_rate_dps", "yaw_rate_dps"});
    if (type == "stationary" || type == "cruise") checkKeys(n, where, {"type", "duration_s"});
    sim::Segment s;
    s.duration_s =
        checkRange(bus::require<double>(n, where, "duration_s"), 1e-3, 1e7, where + ".duration_s");
    if (type == "stationary" || type == "cruise") {
      // constant velocity (zero for stationary): no commands
    } else if (type == "accelerate") {
      s.accel_mps2 = checkRange(bus::require<double>(n, where, "accel_mps2"), -100, 100,
                                where + ".accel_mps2");
    } else if (type ==
               "turn") {  // flat turn: the track and the heading turn together (land vehicle)
      s.heading_rate_radps = s.yaw_rate_radps =
          checkRange(bus::require<double>(n, where, "turn_rate_dps"), -90, 90,
                     where + ".turn_rate_dps") *
          kDeg;
    } else if (type == "climb") {  // flight path and pitch change together
      s.climb_rate_radps = s.pitch_rate_radps =
          checkRange(bus::require<double>(n, where, "climb_rate_dps"), -30, 30,
                     where + ".climb_rate_dps") *
          kDeg;
    } else if (type == "coordinated_turn") {
      // Roll in to the bank of a coordinated turn (tan(bank) = v * rate / g), turn, roll out.
      const double rate = checkRange(bus::require<double>(n, where, "turn_rate_dps"), -30, 30,
                                     where + ".turn_rate_dps") *
                          kDeg;
      const double speed =
          checkRange(bus::require<double>(n, where, "speed_mps"), 0, 1000, where + ".speed_mps");
      const double roll_time =
          checkRange(get<double>(n, where, "roll_time_s", 3.0), 0.1, 60, where + ".roll_time_s");
      if (s.duration_s <= 2 * roll_time)
        throw ConfigError("configuration " + where + ".duration_s must exceed twice roll_time_s");
      const double bank = std::atan(speed * rate / kG);
      sim::Segment in{roll_time};
      in.roll_rate_radps = bank / roll_time;
      sim::Segment turn{s.duration_s - 2 * roll_time};
      turn.heading_rate_radps = turn.yaw_rate_radps = rate;
      sim::Segment out_seg{roll_time};
      out_seg.roll_rate_radps = -bank / roll_time;
      out.push_back(in);
      out.push_back(turn);
      out.push_back(out_seg);
      continue;
    } else if (type == "attitude") {  // attitude manoeuvre, velocity unchanged (seed 000)
      s.roll_rate_radps = get<double>(n, where, "roll_rate_dps", 0.0) * kDeg;
      s.pitch_rate_radps = get<double>(n, where, "pitch_rate_dps", 0.0) * kDeg;
      s.yaw_rate_radps = get<double>(n, where, "yaw_rate_dps", 0.0) * kDeg;
    } else {
      throw ConfigError(
          "configuration " + where + ".type = '" + type +
          "' is not stationary, accelerate, cruise, turn, climb, coordinated_turn or attitude");
    }
    out.push_back(s);
  }
  return out;
}

void checkImuKeys(const YAML::Node& imu) {
  checkKeys(
      imu, "imu",
      {"accel_bias_ug", "accel_bias_sigma_ug", "accel_bias_instability_ug",
       "accel_noise_ug_per_sqrthz", "accel_vrw_ug_per_sqrth", "accel_scale_factor_ppm",
       "accel_misalignment_urad", "accel_quantum_mps", "gyro_bias_deg_per_h",
       "gyro_bias_sigma_deg_per_h", "gyro_bias_instability_deg_per_h", "gyro_arw_deg_per_sqrth",
       "gyro_noise_dps_per_sqrthz", "gyro_scale_factor_ppm", "gyro_misalignment_urad",
       "gyro_quantum_urad", "gyro_g_sensitivity_deg_per_h_per_g", "bias_correlation_time_s"});
}

/// The keys every fault has.
constexpr std::initializer_list<const char*> kFaultCommonKeys = {"type", "start_s", "end_s",
                                                                 "duration_s"};

/// The keys of one fault: the common ones and those of its type.
void checkFaultKeys(const YAML::Node& n, const std::string& where, const std::string& type) {
  if (type == "imu_bias_step")
    checkKeys(n, where, {"sensor", "axis", "magnitude_mg", "magnitude_deg_per_h"},
              kFaultCommonKeys);
  else if (type == "pseudorange_ramp")
    checkKeys(n, where, {"sv_id", "slope_mps", "saturation_m"}, kFaultCommonKeys);
  else if (type == "gnss_position_pulse")
    checkKeys(n, where, {"north_m", "east_m", "down_m"}, kFaultCommonKeys);
  else if (type == "sensor_stuck")
    checkKeys(n, where, {"sensor", "axis"}, kFaultCommonKeys);
  else if (type == "star_tracker_bias")
    checkKeys(n, where, {"bias_arcsec"}, kFaultCommonKeys);
  else
    checkKeys(n, where, kFaultCommonKeys);
}

void parseTriad(const YAML::Node& imu, const std::string& prefix, double bias_unit, double bi_unit,
                double rw_unit, const std::string& rw_key, sim::TriadErrors& t) {
  const std::string w = "imu";
  t.bias = bus::getVector3(imu, w, prefix + "bias" + (prefix == "accel_" ? "_ug" : "_deg_per_h"),
                           bias_unit);
  // Random-constant biases (seeds 000, 004): drawn by the IMU model from the scenario seed, so
  // that --seed N gives new biases.
  const std::string sigma_key = prefix + "bias_sigma" + (prefix == "accel_" ? "_ug" : "_deg_per_h");
  t.random_constant_sigma = get<double>(imu, w, sigma_key, 0.0) * bias_unit;
  t.bias_instability =
      get<double>(imu, w, prefix + "bias_instability" + (prefix == "accel_" ? "_ug" : "_deg_per_h"),
                  0.0) *
      bi_unit;
  t.bias_correlation_time_s = checkRange(get<double>(imu, w, "bias_correlation_time_s", 100.0),
                                         1e-3, 1e7, "imu.bias_correlation_time_s");
  t.random_walk = get<double>(imu, w, rw_key, 0.0) * rw_unit;
  t.scale_factor = bus::getVector3(imu, w, prefix + "scale_factor_ppm", 1e-6);
  const auto mis =
      get<std::vector<double>>(imu, w, prefix + "misalignment_urad", {0, 0, 0, 0, 0, 0});
  if (mis.size() != 6)
    throw ConfigError("configuration imu." + prefix +
                      "misalignment_urad must have 6 elements (xy xz yx yz zx zy)");
  for (int i = 0; i < 6; ++i) t.misalignment[i] = mis[static_cast<std::size_t>(i)] * 1e-6;
}

sim::FaultSchedule parseFaults(const YAML::Node& list) {
  std::vector<sim::Fault> out;
  if (!list || list.IsNull()) return sim::FaultSchedule{};
  if (!list.IsSequence()) throw ConfigError("configuration faults must be a list");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node n = list[i];
    const std::string where = "faults[" + std::to_string(i) + "]";
    const std::string type = bus::require<std::string>(n, where, "type");
    checkFaultKeys(n, where, type);
    sim::Fault f;
    f.start_s = checkRange(bus::require<double>(n, where, "start_s"), 0, 1e7, where + ".start_s");
    if (n["end_s"])
      f.end_s = checkRange(get<double>(n, where, "end_s", 0), f.start_s, 1e7, where + ".end_s");
    if (n["duration_s"])
      f.end_s = f.start_s +
                checkRange(get<double>(n, where, "duration_s", 0), 0, 1e7, where + ".duration_s");
    if (type == "imu_bias_step") {
      f.kind = sim::FaultKind::kImuBiasStep;
      f.sensor = sensorKind(n, where);
      f.axis = axisIndex(n, where);
      f.magnitude = f.sensor == sim::SensorKind::kAccelerometer
                        ? bus::require<double>(n, where, "magnitude_mg") * 1e-3 * kG
                        : bus::require<double>(n, where, "magnitude_deg_per_h") * kDegPerHour;
    } else if (type == "pseudorange_ramp") {
      f.kind = sim::FaultKind::kPseudorangeRamp;
      f.sv_id = static_cast<int>(
          checkRange(bus::require<int>(n, where, "sv_id"), 1, 32, where + ".sv_id"));
      f.slope = bus::require<double>(n, where, "slope_mps");
      f.saturation =
          checkRange(get<double>(n, where, "saturation_m", 0.0), 0, 1e7, where + ".saturation_m");
    } else if (type == "gnss_position_pulse") {
      f.kind = sim::FaultKind::kGnssPositionPulse;
      f.vector = Eigen::Vector3d(get<double>(n, where, "north_m", 0.0),
                                 get<double>(n, where, "east_m", 0.0),
                                 get<double>(n, where, "down_m", 0.0));
    } else if (type == "sensor_stuck") {
      f.kind = sim::FaultKind::kSensorStuck;
      f.sensor = sensorKind(n, where);
      f.axis = axisIndex(n, where);
    } else if (type == "gnss_outage") {
      f.kind = sim::FaultKind::kGnssOutage;
    } else if (type == "star_tracker_outage") {
      f.kind = sim::FaultKind::kStarTrackerOutage;
    } else if (type == "star_tracker_bias") {
      f.kind = sim::FaultKind::kStarTrackerBias;
      f.vector = bus::getVector3(n, where, "bias_arcsec", kArcsec);
    } else {
      throw ConfigError("configuration " + where + ".type = '" + type + "' is not a known fault");
    }
    out.push_back(f);
  }
  return sim::FaultSchedule(out);
}
}  // namespace

SimConfig parseSimConfig(const YAML::Node& root) {
  SimConfig c;
  auto& s = c.scenario;
  checkKeys(root, "",
            {"name", "seed", "vehicle", "orbit", "gravity", "timing", "imu", "dither", "vibration",
             "gnss", "star_tracker", "faults", "ids", "publish"},
            bus::kParticipantKeys);
  s.name = get<std::string>(root, "", "name", "default");
  s.seed = get<std::uint64_t>(root, "", "seed", 1);

  const YAML::Node veh = root["vehicle"];
  const YAML::Node orbit = root["orbit"];
  if (veh && orbit) throw ConfigError("configuration has both vehicle and orbit; choose one");
  if (orbit) {
    checkKeys(orbit, "orbit", {"altitude_km", "inclination_deg", "latitude_deg", "longitude_deg"});
    s.orbit = true;
    s.orbit_start.altitude_m = checkRange(bus::require<double>(orbit, "orbit", "altitude_km"), 100,
                                          50000, "orbit.altitude_km") *
                               1e3;
    s.orbit_start.inclination_rad =
        checkRange(bus::require<double>(orbit, "orbit", "inclination_deg"), 0, 180,
                   "orbit.inclination_deg") *
        kDeg;
    s.orbit_start.latitude_rad = checkRange(bus::require<double>(orbit, "orbit", "latitude_deg"),
                                            -90, 90, "orbit.latitude_deg") *
                                 kDeg;
    s.orbit_start.longitude_rad = checkRange(bus::require<double>(orbit, "orbit", "longitude_deg"),
                                             -180, 180, "orbit.longitude_deg") *
                                  kDeg;
    if (std::abs(s.orbit_start.latitude_rad) > s.orbit_start.inclination_rad) {
      throw ConfigError("configuration orbit.latitude_deg exceeds orbit.inclination_deg");
    }
    s.gravity = core::earth::GravityModel::kPointMass;  // seed 001: spherical Earth
  } else {
    checkKeys(veh, "vehicle",
              {"latitude_deg", "longitude_deg", "height_m", "roll_deg", "pitch_deg", "yaw_deg",
               "speed_mps", "heading_deg", "flight_path_deg", "segments"});
    const core::earth::Geodetic default_site{36.5 * kDeg, 127.5 * kDeg, 100.0};  // seed 000
    s.vehicle.position = bus::getGeodeticDeg(veh, "vehicle", &default_site);
    s.vehicle.roll_pitch_yaw_rad = bus::getRollPitchYawDeg(veh, "vehicle");
    s.vehicle.speed_mps =
        checkRange(get<double>(veh, "vehicle", "speed_mps", 0.0), 0, 1e4, "vehicle.speed_mps");
    s.vehicle.heading_rad =
        get<double>(veh, "vehicle", "heading_deg", s.vehicle.roll_pitch_yaw_rad.z() / kDeg) * kDeg;
    s.vehicle.flight_path_rad = get<double>(veh, "vehicle", "flight_path_deg", 0.0) * kDeg;
    s.segments = parseSegments(child(veh, "segments"));
  }
  const std::string gravity =
      get<std::string>(root, "", "gravity", s.orbit ? "point_mass" : "wgs84");
  if (gravity == "wgs84")
    s.gravity = core::earth::GravityModel::kWgs84Normal;
  else if (gravity == "point_mass")
    s.gravity = core::earth::GravityModel::kPointMass;
  else
    throw ConfigError("configuration gravity = '" + gravity + "' is not wgs84 or point_mass");

  const YAML::Node timing = root["timing"];
  checkKeys(timing, "timing",
            {"start", "duration_s", "pacing", "fast_pacing_block_s", "wait_for_readers_s",
             "min_readers", "imu_rate_hz", "raw_rate_hz", "gnss_rate_hz", "star_tracker_rate_hz"});
  const std::string start = get<std::string>(timing, "timing", "start", "now");
  if (start == "now") {
    c.start_now = true;
  } else {
    c.start_now = false;
    try {
      s.start_time_ns = static_cast<std::int64_t>(std::stoull(start));
    } catch (const std::exception&) {
      throw ConfigError("configuration timing.start = '" + start +
                        "' is neither 'now' nor GPS nanoseconds");
    }
  }
  c.duration_s =
      checkRange(get<double>(timing, "timing", "duration_s", 0.0), 0, 1e7, "timing.duration_s");
  const std::string pacing = get<std::string>(timing, "timing", "pacing", "realtime");
  if (pacing == "realtime")
    c.pacing = Pacing::kRealTime;
  else if (pacing == "fast")
    c.pacing = Pacing::kFast;
  else
    throw ConfigError("configuration timing.pacing = '" + pacing + "' is not realtime or fast");
  c.fast_pacing_block_s =
      get<double>(timing, "timing", "fast_pacing_block_s", SimConfig{}.fast_pacing_block_s);
  c.wait_for_readers_s = checkRange(get<double>(timing, "timing", "wait_for_readers_s", 10.0), 0,
                                    3600, "timing.wait_for_readers_s");
  const YAML::Node wait = child(timing, "min_readers");
  checkKeys(wait, "timing.min_readers", {"imu", "raw_imu", "gnss", "star_tracker"});
  auto readers = [&](const char* key, int fallback) {
    return static_cast<int>(checkRange(get<int>(wait, "timing.min_readers", key, fallback), 0, 64,
                                       std::string("timing.min_readers.") + key));
  };
  c.min_readers.imu = readers("imu", 1);
  c.min_readers.raw_imu = readers("raw_imu", 0);
  c.min_readers.gnss = readers("gnss", 1);
  c.min_readers.star_tracker = readers("star_tracker", 1);
  const double imu_hz = checkRange(get<double>(timing, "timing", "imu_rate_hz", 100.0), 1, 2000,
                                   "timing.imu_rate_hz");
  const double period_ns = 1e9 / imu_hz;
  if (std::abs(period_ns - std::round(period_ns)) > 1e-6) {
    throw ConfigError("configuration timing.imu_rate_hz = " + std::to_string(imu_hz) +
                      " does not give an integer period in nanoseconds");
  }
  s.imu_period_ns = std::llround(period_ns);
  const double raw_hz = checkRange(get<double>(timing, "timing", "raw_rate_hz", 2400.0), 1, 10000,
                                   "timing.raw_rate_hz");
  s.raw_samples_per_increment =
      ratio(raw_hz, imu_hz, "timing.imu_rate_hz (raw_rate_hz / imu_rate_hz)");
  if (s.raw_samples_per_increment > 256) {
    throw ConfigError("configuration timing.raw_rate_hz / imu_rate_hz = " +
                      std::to_string(s.raw_samples_per_increment) +
                      " exceeds 256 samples per block");
  }
  const double gnss_hz =
      checkRange(get<double>(timing, "timing", "gnss_rate_hz", 1.0), 0, 100, "timing.gnss_rate_hz");
  s.gnss_every_n_increments = gnss_hz > 0 ? ratio(imu_hz, gnss_hz, "timing.gnss_rate_hz") : 0;
  const double st_hz = checkRange(get<double>(timing, "timing", "star_tracker_rate_hz", 5.0), 0,
                                  100, "timing.star_tracker_rate_hz");
  s.star_tracker_every_n_increments =
      st_hz > 0 ? ratio(imu_hz, st_hz, "timing.star_tracker_rate_hz") : 0;

  const YAML::Node imu = root["imu"];
  checkImuKeys(imu);
  parseTriad(imu, "accel_", kMicroG, kMicroG, kMicroG, "accel_noise_ug_per_sqrthz", s.imu.accel);
  parseTriad(imu, "gyro_", kDegPerHour, kDegPerHour, kDeg / 60.0, "gyro_arw_deg_per_sqrth",
             s.imu.gyro);
  // Seed 004 gives the gyro white noise as a rate density [deg/s/sqrt(Hz)]; same quantity.
  if (imu && imu["gyro_noise_dps_per_sqrthz"]) {
    s.imu.gyro.random_walk = get<double>(imu, "imu", "gyro_noise_dps_per_sqrthz", 0.0) * kDeg;
  }
  // Velocity random walk may also be given per sqrt(h) (seed 001: 10 ug/sqrt(h)).
  if (imu && imu["accel_vrw_ug_per_sqrth"]) {
    s.imu.accel.random_walk =
        get<double>(imu, "imu", "accel_vrw_ug_per_sqrth", 0.0) * kMicroG / 60.0;
  }
  s.imu.gyro_g_sensitivity.diagonal() =
      bus::getVector3(imu, "imu", "gyro_g_sensitivity_deg_per_h_per_g", kDegPerHour / kG);
  s.imu.accel.quantum = get<double>(imu, "imu", "accel_quantum_mps", 0.0);
  s.imu.gyro.quantum = get<double>(imu, "imu", "gyro_quantum_urad", 0.0) * 1e-6;

  const YAML::Node dither = root["dither"];
  checkKeys(dither, "dither",
            {"enabled", "frequencies_hz", "peak_rate_min_dps", "peak_rate_max_dps",
             "accel_cross_axis_mg", "accel_own_axis_mg", "trapping_rate_dps"});
  s.dither = get<bool>(dither, "dither", "enabled", false);
  s.dither_spec.frequency_hz =
      bus::getVector3(dither, "dither", "frequencies_hz", 1.0, s.dither_spec.frequency_hz);
  s.dither_spec.peak_rate_min_radps =
      get<double>(dither, "dither", "peak_rate_min_dps", 70.0) * kDeg;
  s.dither_spec.peak_rate_max_radps =
      get<double>(dither, "dither", "peak_rate_max_dps", 130.0) * kDeg;
  if (s.dither_spec.peak_rate_min_radps > s.dither_spec.peak_rate_max_radps) {
    throw ConfigError("configuration dither.peak_rate_min_dps exceeds dither.peak_rate_max_dps");
  }
  for (int i = 0; i < 3; ++i) {
    if (s.dither && s.dither_spec.frequency_hz[i] * 2 >= raw_hz) {
      throw ConfigError("configuration dither.frequencies_hz[" + std::to_string(i) +
                        "] = " + std::to_string(s.dither_spec.frequency_hz[i]) +
                        " is above the raw Nyquist frequency");
    }
  }
  s.dither_spec.accel_cross_axis_mps2 =
      get<double>(dither, "dither", "accel_cross_axis_mg", 5.0) * 1e-3 * kG;
  s.dither_spec.accel_own_axis_mps2 =
      get<double>(dither, "dither", "accel_own_axis_mg", 1.0) * 1e-3 * kG;
  s.dither_spec.trapping_rate_radps =
      get<double>(dither, "dither", "trapping_rate_dps", 0.5) * kDeg;

  const YAML::Node vib = root["vibration"];
  checkKeys(vib, "vibration",
            {"enabled", "accel_rms_mg", "gyro_rms_dps", "isolator_corner_hz", "moving_speed_mps"});
  s.vibration.enabled = get<bool>(vib, "vibration", "enabled", false);
  s.vibration.accel_rms_mps2 = checkRange(get<double>(vib, "vibration", "accel_rms_mg",
                                                      s.vibration.accel_rms_mps2 / units::kMilliG),
                                          0.0, 1e4, "vibration.accel_rms_mg") *
                               units::kMilliG;
  s.vibration.gyro_rms_radps =
      checkRange(get<double>(vib, "vibration", "gyro_rms_dps", s.vibration.gyro_rms_radps / kDeg),
                 0.0, 1e3, "vibration.gyro_rms_dps") *
      kDeg;
  s.vibration.isolator_corner_hz =
      get<double>(vib, "vibration", "isolator_corner_hz", s.vibration.isolator_corner_hz);
  if (s.vibration.enabled) {  // the corner must lie below the raw stream's Nyquist frequency
    checkRange(s.vibration.isolator_corner_hz, 0.1, raw_hz / 2.0 * 0.9,
               "vibration.isolator_corner_hz");
  }
  s.vibration.moving_speed_mps =
      checkRange(get<double>(vib, "vibration", "moving_speed_mps", s.vibration.moving_speed_mps),
                 0.0, 1e3, "vibration.moving_speed_mps");

  const YAML::Node gnss = root["gnss"];
  checkKeys(
      gnss, "gnss",
      {"planes", "satellites_per_plane", "eccentricity", "elevation_mask_deg", "max_satellites",
       "fixed_satellites", "clock_bias_m", "clock_drift_mps", "clock_bias_noise_m_per_sqrts",
       "clock_drift_noise_mps_per_sqrts", "pseudorange_sigma_m", "pseudorange_rate_sigma_mps",
       "fix", "fix_position_sigma_m", "fix_velocity_sigma_mps"});
  s.constellation.planes =
      static_cast<int>(checkRange(get<int>(gnss, "gnss", "planes", 6), 1, 8, "gnss.planes"));
  s.constellation.satellites_per_plane = static_cast<int>(checkRange(
      get<int>(gnss, "gnss", "satellites_per_plane", 4), 1, 5, "gnss.satellites_per_plane"));
  s.constellation.eccentricity =
      checkRange(get<double>(gnss, "gnss", "eccentricity", 0.0), 0, 0.1, "gnss.eccentricity");
  s.gnss.elevation_mask_rad = checkRange(get<double>(gnss, "gnss", "elevation_mask_deg", 5.0), -90,
                                         60, "gnss.elevation_mask_deg") *
                              kDeg;
  s.gnss.max_satellites = static_cast<int>(
      checkRange(get<int>(gnss, "gnss", "max_satellites", 12), 1, 32, "gnss.max_satellites"));
  s.gnss.fixed_satellites = static_cast<int>(
      checkRange(get<int>(gnss, "gnss", "fixed_satellites", 0), 0, 32, "gnss.fixed_satellites"));
  s.gnss.clock_bias_m = get<double>(gnss, "gnss", "clock_bias_m", 3000.0);
  s.gnss.clock_drift_mps = get<double>(gnss, "gnss", "clock_drift_mps", 1.0);
  s.gnss.clock_bias_noise_m_per_sqrts =
      checkRange(get<double>(gnss, "gnss", "clock_bias_noise_m_per_sqrts", 0.0), 0, 1e3,
                 "gnss.clock_bias_noise_m_per_sqrts");
  s.gnss.clock_drift_noise_mps_per_sqrts =
      checkRange(get<double>(gnss, "gnss", "clock_drift_noise_mps_per_sqrts", 0.0), 0, 1e2,
                 "gnss.clock_drift_noise_mps_per_sqrts");
  s.gnss.pseudorange_sigma_m = checkRange(get<double>(gnss, "gnss", "pseudorange_sigma_m", 3.0),
                                          1e-3, 1e3, "gnss.pseudorange_sigma_m");
  s.gnss.pseudorange_rate_sigma_mps =
      checkRange(get<double>(gnss, "gnss", "pseudorange_rate_sigma_mps", 0.05), 1e-4, 100,
                 "gnss.pseudorange_rate_sigma_mps");
  const std::string fix = get<std::string>(gnss, "gnss", "fix", "least_squares");
  if (fix != "least_squares" && fix != "error_model") {
    throw ConfigError("configuration gnss.fix = '" + fix + "' is not least_squares or error_model");
  }
  s.gnss.fix_least_squares = fix == "least_squares";
  s.gnss.fix_pos_sigma_m = checkRange(get<double>(gnss, "gnss", "fix_position_sigma_m", 2.5), 1e-3,
                                      1e3, "gnss.fix_position_sigma_m");
  s.gnss.fix_vel_sigma_mps = checkRange(get<double>(gnss, "gnss", "fix_velocity_sigma_mps", 0.1),
                                        1e-4, 100, "gnss.fix_velocity_sigma_mps");

  const YAML::Node st = root["star_tracker"];
  checkKeys(st, "star_tracker",
            {"sigma_arcsec", "bias_arcsec", "bias_correlation_time_s", "dropout_probability"});
  s.star_tracker.noise_rad = checkRange(get<double>(st, "star_tracker", "sigma_arcsec", 0.3), 0,
                                        3600, "star_tracker.sigma_arcsec") *
                             kArcsec;
  s.star_tracker.bias_rad = checkRange(get<double>(st, "star_tracker", "bias_arcsec", 0.0), 0, 3600,
                                       "star_tracker.bias_arcsec") *
                            kArcsec;
  s.star_tracker.bias_correlation_time_s =
      checkRange(get<double>(st, "star_tracker", "bias_correlation_time_s", 300.0), 1e-3, 1e7,
                 "star_tracker.bias_correlation_time_s");
  s.star_tracker.dropout_probability =
      checkRange(get<double>(st, "star_tracker", "dropout_probability", 0.0), 0, 1,
                 "star_tracker.dropout_probability");

  s.faults = parseFaults(root["faults"]);

  const YAML::Node ids = root["ids"];
  checkKeys(ids, "ids", {"imu", "gnss_receiver", "star_tracker"});
  c.imu_sensor_id = get<std::uint32_t>(ids, "ids", "imu", 1);
  c.gnss_receiver_id = get<std::uint32_t>(ids, "ids", "gnss_receiver", 1);
  c.star_tracker_id = get<std::uint32_t>(ids, "ids", "star_tracker", 1);
  const YAML::Node pub = root["publish"];
  checkKeys(pub, "publish", {"raw_imu", "gnss", "star_tracker"});
  c.publish_raw = get<bool>(pub, "publish", "raw_imu", true);
  c.publish_gnss = get<bool>(pub, "publish", "gnss", s.gnss_every_n_increments > 0);
  c.publish_star_tracker =
      get<bool>(pub, "publish", "star_tracker", s.star_tracker_every_n_increments > 0);
  return c;
}

std::size_t incrementsPerBlock(const SimConfig& c) {
  if (c.pacing != Pacing::kFast || c.fast_pacing_block_s == 0.0) return 0;
  const double rate_hz = 1e9 / static_cast<double>(c.scenario.imu_period_ns);
  const double n = std::round(c.fast_pacing_block_s * rate_hz);
  if (!(n >= 1.0 && n <= static_cast<double>(ImuBlockBatcher::kMaxIncrements))) {
    throw ConfigError(
        "configuration timing.fast_pacing_block_s = " + std::to_string(c.fast_pacing_block_s) +
        " is " + std::to_string(n) + " increments at " + std::to_string(rate_hz) + " Hz, not 1.." +
        std::to_string(ImuBlockBatcher::kMaxIncrements) + " (or 0: one per sample)");
  }
  return static_cast<std::size_t>(n);
}

}  // namespace navbus::sensor_sim
