#include "navbus/sensor_sim/scenario_config.hpp"

#include <algorithm>
#include <cmath>

#include "navbus/bus/config.hpp"
#include "navbus/bus/key_reader.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/core/math/rotation.hpp"
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

void checkImuKeys(const YAML::Node& imu, const std::string& where) {
  checkKeys(
      imu, where,
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
/// The keys every IMU fault has: the common ones and the unit it is addressed to.
constexpr std::initializer_list<const char*> kImuFaultKeys = {"type", "start_s", "end_s",
                                                              "duration_s", "sensor_id"};

/// The keys of one fault: the common ones and those of its type.
void checkFaultKeys(const YAML::Node& n, const std::string& where, const std::string& type) {
  if (type == "imu_bias_step")
    checkKeys(n, where, {"sensor", "axis", "magnitude_mg", "magnitude_deg_per_h"}, kImuFaultKeys);
  else if (type == "imu_bias_ramp")
    checkKeys(n, where,
              {"sensor", "axis", "slope_mg_per_s", "slope_deg_per_h_per_s", "saturation_mg",
               "saturation_deg_per_h"},
              kImuFaultKeys);
  else if (type == "pseudorange_ramp")
    checkKeys(n, where, {"sv_id", "slope_mps", "saturation_m", "receiver_id"}, kFaultCommonKeys);
  else if (type == "pseudorange_step")
    checkKeys(n, where, {"sv_id", "magnitude_m", "receiver_id"}, kFaultCommonKeys);
  else if (type == "receiver_clock_jump")
    checkKeys(n, where, {"magnitude_ms", "receiver_id"}, kFaultCommonKeys);
  else if (type == "gnss_outage")
    checkKeys(n, where, {"receiver_id"}, kFaultCommonKeys);
  else if (type == "gnss_position_pulse")
    checkKeys(n, where, {"north_m", "east_m", "down_m"}, kFaultCommonKeys);
  else if (type == "sensor_stuck")
    checkKeys(n, where, {"sensor", "axis"}, kImuFaultKeys);
  else if (type == "imu_scale_factor_step")
    checkKeys(n, where, {"sensor", "axis", "magnitude_ppm"}, kImuFaultKeys);
  else if (type == "imu_noise_increase")
    checkKeys(n, where, {"sensor", "axis", "factor"}, kImuFaultKeys);
  else if (type == "gnss_multipath")
    checkKeys(n, where, {"sv_id", "amplitude_m", "period_s", "receiver_id"}, kFaultCommonKeys);
  else if (type == "star_tracker_bias")
    checkKeys(n, where, {"bias_arcsec"}, kFaultCommonKeys);
  else
    checkKeys(n, where, kFaultCommonKeys);
}

void parseTriad(const YAML::Node& imu, const std::string& w, const std::string& prefix,
                double bias_unit, double bi_unit, double rw_unit, const std::string& rw_key,
                sim::TriadErrors& t) {
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
                                         1e-3, 1e7, w + ".bias_correlation_time_s");
  t.random_walk = get<double>(imu, w, rw_key, 0.0) * rw_unit;
  t.scale_factor = bus::getVector3(imu, w, prefix + "scale_factor_ppm", units::kPpm);
  const auto mis =
      get<std::vector<double>>(imu, w, prefix + "misalignment_urad", {0, 0, 0, 0, 0, 0});
  if (mis.size() != 6)
    throw ConfigError("configuration " + w + "." + prefix +
                      "misalignment_urad must have 6 elements (xy xz yx yz zx zy)");
  for (int i = 0; i < 6; ++i) t.misalignment[i] = mis[static_cast<std::size_t>(i)] * 1e-6;
}

/// The unit an IMU fault's `sensor_id` names (absent: the scenario's IMU, unit 0), among
/// `imu_ids` (unit k's sensor id at k).
int faultUnit(const YAML::Node& n, const std::string& where,
              const std::vector<std::uint32_t>& imu_ids) {
  if (!n["sensor_id"]) return 0;
  const auto id = bus::require<std::uint32_t>(n, where, "sensor_id");
  for (std::size_t k = 0; k < imu_ids.size(); ++k) {
    if (imu_ids[k] == id) return static_cast<int>(k);
  }
  std::string known;
  for (const std::uint32_t i : imu_ids) known += (known.empty() ? "" : ", ") + std::to_string(i);
  throw ConfigError("configuration " + where + ".sensor_id = " + std::to_string(id) +
                    " is not an IMU of the scenario (ids.imu and imu_units: " + known + ")");
}

/// The receiver a pseudorange or clock fault is addressed to (`receiver_id`, default the
/// scenario's receiver): its index in `receiver_ids` (0: the scenario's).
int faultReceiver(const YAML::Node& n, const std::string& where,
                  const std::vector<std::uint32_t>& receiver_ids) {
  if (!n["receiver_id"]) return 0;
  const auto id = bus::require<std::uint32_t>(n, where, "receiver_id");
  for (std::size_t k = 0; k < receiver_ids.size(); ++k) {
    if (receiver_ids[k] == id) return static_cast<int>(k);
  }
  std::string known;
  for (const std::uint32_t i : receiver_ids)
    known += (known.empty() ? "" : ", ") + std::to_string(i);
  throw ConfigError("configuration " + where + ".receiver_id = " + std::to_string(id) +
                    " is not a receiver of the scenario (ids.gnss and gnss_units: " + known + ")");
}

sim::FaultSchedule parseFaults(const YAML::Node& list, const std::vector<std::uint32_t>& imu_ids,
                               const std::vector<std::uint32_t>& receiver_ids) {
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
      f.unit = faultUnit(n, where, imu_ids);
      f.sensor_id = imu_ids[static_cast<std::size_t>(f.unit)];
      f.magnitude = f.sensor == sim::SensorKind::kAccelerometer
                        ? bus::require<double>(n, where, "magnitude_mg") * 1e-3 * kG
                        : bus::require<double>(n, where, "magnitude_deg_per_h") * kDegPerHour;
    } else if (type == "imu_bias_ramp") {
      f.kind = sim::FaultKind::kImuBiasRamp;
      f.sensor = sensorKind(n, where);
      f.axis = axisIndex(n, where);
      f.unit = faultUnit(n, where, imu_ids);
      f.sensor_id = imu_ids[static_cast<std::size_t>(f.unit)];
      const bool accel = f.sensor == sim::SensorKind::kAccelerometer;
      const double unit = accel ? 1e-3 * kG : kDegPerHour;
      f.slope =
          bus::require<double>(n, where, accel ? "slope_mg_per_s" : "slope_deg_per_h_per_s") * unit;
      f.saturation =
          checkRange(get<double>(n, where, accel ? "saturation_mg" : "saturation_deg_per_h", 0.0),
                     0, 1e9, where + (accel ? ".saturation_mg" : ".saturation_deg_per_h")) *
          unit;
    } else if (type == "pseudorange_ramp" || type == "pseudorange_step") {
      const bool ramp = type == "pseudorange_ramp";
      f.kind = ramp ? sim::FaultKind::kPseudorangeRamp : sim::FaultKind::kPseudorangeStep;
      f.receiver = faultReceiver(n, where, receiver_ids);
      f.receiver_id = receiver_ids[static_cast<std::size_t>(f.receiver)];
      f.sv_id = static_cast<int>(
          checkRange(bus::require<int>(n, where, "sv_id"), 1, 32, where + ".sv_id"));
      if (!ramp) {
        f.magnitude = bus::require<double>(n, where, "magnitude_m");
        out.push_back(f);
        continue;
      }
      f.slope = bus::require<double>(n, where, "slope_mps");
      f.saturation =
          checkRange(get<double>(n, where, "saturation_m", 0.0), 0, 1e7, where + ".saturation_m");
    } else if (type == "receiver_clock_jump") {
      f.kind = sim::FaultKind::kReceiverClockJump;
      f.receiver = faultReceiver(n, where, receiver_ids);
      f.receiver_id = receiver_ids[static_cast<std::size_t>(f.receiver)];
      f.magnitude =
          bus::require<double>(n, where, "magnitude_ms") * 1e-3 * core::earth::kSpeedOfLight_mps;
    } else if (type == "gnss_position_pulse") {
      f.kind = sim::FaultKind::kGnssPositionPulse;
      f.vector = Eigen::Vector3d(get<double>(n, where, "north_m", 0.0),
                                 get<double>(n, where, "east_m", 0.0),
                                 get<double>(n, where, "down_m", 0.0));
    } else if (type == "sensor_stuck") {
      f.kind = sim::FaultKind::kSensorStuck;
      f.sensor = sensorKind(n, where);
      f.axis = axisIndex(n, where);
      f.unit = faultUnit(n, where, imu_ids);
      f.sensor_id = imu_ids[static_cast<std::size_t>(f.unit)];
    } else if (type == "imu_scale_factor_step" || type == "imu_noise_increase") {
      const bool scale = type == "imu_scale_factor_step";
      f.kind = scale ? sim::FaultKind::kImuScaleFactorStep : sim::FaultKind::kImuNoiseIncrease;
      f.sensor = sensorKind(n, where);
      f.axis = axisIndex(n, where);
      f.unit = faultUnit(n, where, imu_ids);
      f.sensor_id = imu_ids[static_cast<std::size_t>(f.unit)];
      f.magnitude =
          scale ? checkRange(bus::require<double>(n, where, "magnitude_ppm"), -1e5, 1e5,
                             where + ".magnitude_ppm") *
                      1e-6
                : checkRange(bus::require<double>(n, where, "factor"), 1.0, 1e4, where + ".factor");
    } else if (type == "gnss_multipath") {
      f.kind = sim::FaultKind::kGnssMultipath;
      f.receiver = faultReceiver(n, where, receiver_ids);
      f.receiver_id = receiver_ids[static_cast<std::size_t>(f.receiver)];
      f.sv_id = static_cast<int>(
          checkRange(bus::require<int>(n, where, "sv_id"), 1, 32, where + ".sv_id"));
      f.magnitude = checkRange(bus::require<double>(n, where, "amplitude_m"), 0.0, 1e4,
                               where + ".amplitude_m");
      f.period_s =
          checkRange(bus::require<double>(n, where, "period_s"), 0.1, 1e5, where + ".period_s");
    } else if (type == "gnss_outage") {
      f.kind = sim::FaultKind::kGnssOutage;
      // One receiver's (receiver_id), or every receiver's.
      f.receiver = n["receiver_id"] ? faultReceiver(n, where, receiver_ids) : -1;
      if (f.receiver >= 0) f.receiver_id = receiver_ids[static_cast<std::size_t>(f.receiver)];
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

namespace {
constexpr bus::FileUnit kDegree{[](double v) { return v * kDeg; }};
constexpr bus::FileUnit kArcsecond{[](double v) { return v * kArcsec; }};
constexpr bus::FileUnit kMilliG{[](double v) { return v * units::kMilliG; }};
constexpr bus::FileUnit kMilliGravity{[](double v) { return v * 1e-3 * kG; }};
constexpr bus::FileUnit kKilometre{[](double v) { return v * 1e3; }};
constexpr bus::FileUnit kMicroGPerSqrtHour{[](double v) { return v * kMicroG / 60.0; }};
constexpr bus::FileUnit kMicroRad{[](double v) { return v * 1e-6; }};
constexpr bus::Range kAny{-1e300, 1e300};

void parseOrbit(const YAML::Node& orbit, sim::ScenarioConfig& s) {
  s.orbit = true;
  bus::KeyReader r(orbit, "orbit");
  for (const char* key : {"altitude_km", "inclination_deg", "latitude_deg", "longitude_deg"}) {
    if (!r.present(key))
      throw ConfigError("configuration orbit." + std::string(key) + " is missing");
  }
  r.number("altitude_km", s.orbit_start.altitude_m, {100, 50000}, kKilometre)
      .number("inclination_deg", s.orbit_start.inclination_rad, {0, 180}, kDegree)
      .number("latitude_deg", s.orbit_start.latitude_rad, {-90, 90}, kDegree)
      .number("longitude_deg", s.orbit_start.longitude_rad, {-180, 180}, kDegree)
      .finish();
  if (std::abs(s.orbit_start.latitude_rad) > s.orbit_start.inclination_rad) {
    throw ConfigError("configuration orbit.latitude_deg exceeds orbit.inclination_deg");
  }
  s.gravity = core::earth::GravityModel::kPointMass;  // seed 001: spherical Earth
}

void parseVehicle(const YAML::Node& veh, sim::ScenarioConfig& s) {
  const core::earth::Geodetic default_site = s.vehicle.position;
  s.vehicle.position = bus::getGeodeticDeg(veh, "vehicle", &default_site);
  s.vehicle.roll_pitch_yaw_rad = bus::getRollPitchYawDeg(veh, "vehicle");
  s.vehicle.heading_rad = s.vehicle.roll_pitch_yaw_rad.z();  // along the body unless given
  bus::KeyReader r(veh, "vehicle");
  r.nested({"latitude_deg", "longitude_deg", "height_m", "roll_deg", "pitch_deg", "yaw_deg",
            "segments"})
      .number("speed_mps", s.vehicle.speed_mps, {0, 1e4})
      .number("heading_deg", s.vehicle.heading_rad, kAny, kDegree)
      .number("flight_path_deg", s.vehicle.flight_path_rad, kAny, kDegree)
      .finish();
  s.segments = parseSegments(child(veh, "segments"));
}

/// "now" or GPS nanoseconds.
void parseStart(const YAML::Node& timing, SimConfig& c) {
  const std::string start = get<std::string>(timing, "timing", "start", "now");
  c.start_now = start == "now";
  if (c.start_now) return;
  try {
    c.scenario.start_time_ns = static_cast<std::int64_t>(std::stoull(start));
  } catch (const std::exception&) {
    throw ConfigError("configuration timing.start = '" + start +
                      "' is neither 'now' nor GPS nanoseconds");
  }
}

/// Sample rates: the IMU's period in whole nanoseconds, the others whole multiples of it.
/// Returns the raw rate [Hz] (the dither and vibration bands are checked against it).
double parseRates(bus::KeyReader& r, sim::ScenarioConfig& s) {
  double imu_hz = 1e9 / static_cast<double>(s.imu_period_ns);
  double raw_hz = imu_hz * s.raw_samples_per_increment;
  double gnss_hz = s.gnss_every_n_increments > 0 ? imu_hz / s.gnss_every_n_increments : 0.0;
  double st_hz =
      s.star_tracker_every_n_increments > 0 ? imu_hz / s.star_tracker_every_n_increments : 0.0;
  r.number("imu_rate_hz", imu_hz, {1, 2000})
      .number("raw_rate_hz", raw_hz, {1, 10000})
      .number("gnss_rate_hz", gnss_hz, {0, 100})
      .number("star_tracker_rate_hz", st_hz, {0, 100});
  const double period_ns = 1e9 / imu_hz;
  if (std::abs(period_ns - std::round(period_ns)) > 1e-6) {
    throw ConfigError("configuration timing.imu_rate_hz = " + std::to_string(imu_hz) +
                      " does not give an integer period in nanoseconds");
  }
  s.imu_period_ns = std::llround(period_ns);
  s.raw_samples_per_increment =
      ratio(raw_hz, imu_hz, "timing.imu_rate_hz (raw_rate_hz / imu_rate_hz)");
  if (s.raw_samples_per_increment > 256) {
    throw ConfigError("configuration timing.raw_rate_hz / imu_rate_hz = " +
                      std::to_string(s.raw_samples_per_increment) +
                      " exceeds 256 samples per block");
  }
  s.gnss_every_n_increments = gnss_hz > 0 ? ratio(imu_hz, gnss_hz, "timing.gnss_rate_hz") : 0;
  s.star_tracker_every_n_increments =
      st_hz > 0 ? ratio(imu_hz, st_hz, "timing.star_tracker_rate_hz") : 0;
  return raw_hz;
}

double parseTiming(const YAML::Node& timing, SimConfig& c) {
  parseStart(timing, c);
  bus::KeyReader r(timing, "timing");
  r.nested({"start", "min_readers"})
      .number("duration_s", c.duration_s, {0, 1e7})
      .choice("pacing", c.pacing, {{"realtime", Pacing::kRealTime}, {"fast", Pacing::kFast}})
      .number("fast_pacing_block_s", c.fast_pacing_block_s, kAny)
      .number("wait_for_readers_s", c.wait_for_readers_s, {0, 3600});
  const double raw_hz = parseRates(r, c.scenario);
  r.finish();
  bus::KeyReader readers(child(timing, "min_readers"), "timing.min_readers");
  readers.integer("imu", c.min_readers.imu, {0, 64})
      .integer("raw_imu", c.min_readers.raw_imu, {0, 64})
      .integer("gnss", c.min_readers.gnss, {0, 64});
  c.min_readers.gnss_fix = c.min_readers.gnss;  // unless said apart
  readers.integer("gnss_fix", c.min_readers.gnss_fix, {0, 64})
      .integer("star_tracker", c.min_readers.star_tracker, {0, 64})
      .finish();
  return raw_hz;
}

void parseImu(const YAML::Node& imu, const std::string& where, sim::ImuSpec& spec) {
  checkImuKeys(imu, where);
  parseTriad(imu, where, "accel_", kMicroG, kMicroG, kMicroG, "accel_noise_ug_per_sqrthz",
             spec.accel);
  parseTriad(imu, where, "gyro_", kDegPerHour, kDegPerHour, kDeg / 60.0, "gyro_arw_deg_per_sqrth",
             spec.gyro);
  bus::KeyReader r(imu, where);
  // Seed 004 gives the gyro white noise as a rate density [deg/s/sqrt(Hz)]; same quantity.
  r.number("gyro_noise_dps_per_sqrthz", spec.gyro.random_walk, kAny, kDegree)
      // Velocity random walk may also be given per sqrt(h) (seed 001: 10 ug/sqrt(h)).
      .number("accel_vrw_ug_per_sqrth", spec.accel.random_walk, kAny, kMicroGPerSqrtHour)
      .number("accel_quantum_mps", spec.accel.quantum, kAny)
      .number("gyro_quantum_urad", spec.gyro.quantum, kAny, kMicroRad);
  spec.gyro_g_sensitivity.diagonal() =
      bus::getVector3(imu, where, "gyro_g_sensitivity_deg_per_h_per_g", kDegPerHour / kG);
}

/// Further IMU units (a redundant installation): their sensor ids (after the scenario's IMU's
/// in `imu_ids`), mountings, lever arms and error models (the scenario's `imu` block when a
/// unit has none of its own).
void parseImuUnits(const YAML::Node& list, sim::ScenarioConfig& s,
                   std::vector<std::uint32_t>& imu_ids) {
  if (!list || list.IsNull()) return;
  if (!list.IsSequence()) throw ConfigError("configuration imu_units must be a list");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node n = list[i];
    const std::string where = "imu_units[" + std::to_string(i) + "]";
    checkKeys(n, where, {"sensor_id", "mounting_rpy_deg", "lever_arm_b_m", "imu"});
    const auto id = bus::require<std::uint32_t>(n, where, "sensor_id");
    if (std::find(imu_ids.begin(), imu_ids.end(), id) != imu_ids.end()) {
      throw ConfigError("configuration " + where + ".sensor_id = " + std::to_string(id) +
                        " is already the id of another IMU of the scenario");
    }
    imu_ids.push_back(id);
    sim::ImuUnit u;
    // The unit's axes are the body axes turned by roll, pitch and yaw (as a body's from NED).
    u.c_u_b = core::dcmFromEuler(bus::getVector3(n, where, "mounting_rpy_deg", kDeg)).transpose();
    u.lever_arm_b_m = bus::getVector3(n, where, "lever_arm_b_m", 1.0);
    u.imu = s.imu;
    if (n["imu"]) {
      u.imu = sim::ImuSpec{};
      parseImu(n["imu"], where + ".imu", u.imu);
    }
    s.extra_imus.push_back(u);
  }
}

/// Further GNSS receivers: their ids (after the scenario receiver's in `receiver_ids`), antenna
/// places and clocks.
void parseGnssUnits(const YAML::Node& list, sim::ScenarioConfig& s,
                    std::vector<std::uint32_t>& receiver_ids) {
  if (!list || list.IsNull()) return;
  if (!list.IsSequence()) throw ConfigError("configuration gnss_units must be a list");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node n = list[i];
    const std::string where = "gnss_units[" + std::to_string(i) + "]";
    checkKeys(n, where, {"receiver_id", "antenna_b_m", "clock_bias_m", "clock_drift_mps"});
    const auto id = bus::require<std::uint32_t>(n, where, "receiver_id");
    if (std::find(receiver_ids.begin(), receiver_ids.end(), id) != receiver_ids.end()) {
      throw ConfigError("configuration " + where + ".receiver_id = " + std::to_string(id) +
                        " is already the id of another receiver of the scenario");
    }
    receiver_ids.push_back(id);
    sim::GnssUnit u;
    u.antenna_b_m = bus::getVector3(n, where, "antenna_b_m", 1.0);
    u.clock_bias_m = checkRange(get<double>(n, where, "clock_bias_m", s.gnss.clock_bias_m), -1e9,
                                1e9, where + ".clock_bias_m");
    u.clock_drift_mps = checkRange(get<double>(n, where, "clock_drift_mps", s.gnss.clock_drift_mps),
                                   -1e6, 1e6, where + ".clock_drift_mps");
    s.extra_receivers.push_back(u);
  }
}

void parseDither(const YAML::Node& dither, double raw_hz, sim::ScenarioConfig& s) {
  sim::DitherSpec& d = s.dither_spec;
  bus::KeyReader r(dither, "dither");
  r.value("enabled", s.dither)
      .nested({"frequencies_hz"})
      .number("peak_rate_min_dps", d.peak_rate_min_radps, kAny, kDegree)
      .number("peak_rate_max_dps", d.peak_rate_max_radps, kAny, kDegree)
      .number("accel_cross_axis_mg", d.accel_cross_axis_mps2, kAny, kMilliGravity)
      .number("accel_own_axis_mg", d.accel_own_axis_mps2, kAny, kMilliGravity)
      .number("trapping_rate_dps", d.trapping_rate_radps, kAny, kDegree)
      .finish();
  d.frequency_hz = bus::getVector3(dither, "dither", "frequencies_hz", 1.0, d.frequency_hz);
  if (d.peak_rate_min_radps > d.peak_rate_max_radps) {
    throw ConfigError("configuration dither.peak_rate_min_dps exceeds dither.peak_rate_max_dps");
  }
  for (int i = 0; i < 3; ++i) {
    if (s.dither && d.frequency_hz[i] * 2 >= raw_hz) {
      throw ConfigError("configuration dither.frequencies_hz[" + std::to_string(i) + "] = " +
                        std::to_string(d.frequency_hz[i]) + " is above the raw Nyquist frequency");
    }
  }
}

void parseVibration(const YAML::Node& vib, double raw_hz, sim::VibrationSpec& v) {
  bus::KeyReader r(vib, "vibration");
  r.value("enabled", v.enabled)
      .number("accel_rms_mg", v.accel_rms_mps2, {0.0, 1e4}, kMilliG)
      .number("gyro_rms_dps", v.gyro_rms_radps, {0.0, 1e3}, kDegree)
      .number("isolator_corner_hz", v.isolator_corner_hz, kAny)
      .number("moving_speed_mps", v.moving_speed_mps, {0.0, 1e3})
      .finish();
  if (v.enabled) {  // the corner must lie below the raw stream's Nyquist frequency
    checkRange(v.isolator_corner_hz, 0.1, raw_hz / 2.0 * 0.9, "vibration.isolator_corner_hz");
  }
}

void parseGnss(const YAML::Node& gnss, sim::ScenarioConfig& s) {
  sim::GnssReceiverConfig& g = s.gnss;
  bus::KeyReader r(gnss, "gnss");
  r.integer("planes", s.constellation.planes, {1, 8})
      .integer("satellites_per_plane", s.constellation.satellites_per_plane, {1, 5})
      .number("eccentricity", s.constellation.eccentricity, {0, 0.1})
      .number("elevation_mask_deg", g.elevation_mask_rad, {-90, 60}, kDegree)
      .integer("max_satellites", g.max_satellites, {1, 32})
      .integer("fixed_satellites", g.fixed_satellites, {0, 32})
      .number("clock_bias_m", g.clock_bias_m, kAny)
      .number("clock_drift_mps", g.clock_drift_mps, kAny)
      .number("clock_bias_noise_m_per_sqrts", g.clock_bias_noise_m_per_sqrts, {0, 1e3})
      .number("clock_drift_noise_mps_per_sqrts", g.clock_drift_noise_mps_per_sqrts, {0, 1e2})
      .number("pseudorange_sigma_m", g.pseudorange_sigma_m, {1e-3, 1e3})
      .number("pseudorange_rate_sigma_mps", g.pseudorange_rate_sigma_mps, {1e-4, 100})
      .choice("fix", g.fix_least_squares, {{"least_squares", true}, {"error_model", false}})
      .number("fix_position_sigma_m", g.fix_pos_sigma_m, {1e-3, 1e3})
      .number("fix_velocity_sigma_mps", g.fix_vel_sigma_mps, {1e-4, 100})
      .finish();
}

void parseStarTracker(const YAML::Node& st, sim::StarTrackerSpec& t) {
  bus::KeyReader r(st, "star_tracker");
  r.number("sigma_arcsec", t.noise_rad, {0, 3600}, kArcsecond)
      .number("bias_arcsec", t.bias_rad, {0, 3600}, kArcsecond)
      .number("bias_correlation_time_s", t.bias_correlation_time_s, {1e-3, 1e7})
      .number("dropout_probability", t.dropout_probability, {0, 1})
      .finish();
}

/// Instance keys, and which streams are published (GNSS and star tracker: when they have a
/// rate, unless said otherwise).
void parseOutputs(const YAML::Node& root, SimConfig& c) {
  bus::KeyReader ids(root["ids"], "ids");
  ids.value("imu", c.imu_sensor_id)
      .value("gnss_receiver", c.gnss_receiver_id)
      .value("star_tracker", c.star_tracker_id)
      .finish();
  c.publish_gnss = c.scenario.gnss_every_n_increments > 0;
  c.publish_star_tracker = c.scenario.star_tracker_every_n_increments > 0;
  bus::KeyReader publish(root["publish"], "publish");
  publish.value("raw_imu", c.publish_raw)
      .value("gnss", c.publish_gnss)
      .value("star_tracker", c.publish_star_tracker)
      .finish();
}
}  // namespace

SimConfig parseSimConfig(const YAML::Node& root) {
  bus::requireMapOrAbsent(root, "");
  const YAML::Node veh = root["vehicle"];
  const YAML::Node orbit = root["orbit"];
  if (veh && orbit) throw ConfigError("configuration has both vehicle and orbit; choose one");
  SimConfig c;
  sim::ScenarioConfig& s = c.scenario;
  bus::KeyReader top(root, "");
  top.value("name", s.name)
      .value("seed", s.seed)
      .nested({"vehicle", "orbit", "timing", "imu", "imu_units", "dither", "vibration", "gnss",
               "gnss_units", "star_tracker", "faults", "ids", "publish"});
  if (orbit) {
    parseOrbit(orbit, s);
  } else {
    parseVehicle(veh, s);
  }
  top.choice("gravity", s.gravity,
             {{"wgs84", core::earth::GravityModel::kWgs84Normal},
              {"point_mass", core::earth::GravityModel::kPointMass}})
      .finish(bus::kParticipantKeys);
  const double raw_hz = parseTiming(root["timing"], c);
  parseImu(root["imu"], "imu", s.imu);
  parseDither(root["dither"], raw_hz, s);
  parseVibration(root["vibration"], raw_hz, s.vibration);
  parseGnss(root["gnss"], s);
  parseStarTracker(root["star_tracker"], s.star_tracker);
  parseOutputs(root, c);
  std::vector<std::uint32_t> imu_ids{c.imu_sensor_id};
  parseImuUnits(root["imu_units"], s, imu_ids);
  c.extra_imu_sensor_ids.assign(imu_ids.begin() + 1, imu_ids.end());
  std::vector<std::uint32_t> receiver_ids{c.gnss_receiver_id};
  parseGnssUnits(root["gnss_units"], s, receiver_ids);
  c.extra_gnss_receiver_ids.assign(receiver_ids.begin() + 1, receiver_ids.end());
  s.faults = parseFaults(root["faults"], imu_ids, receiver_ids);
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
