#include "navbus/importers/dataset.hpp"

#include "navbus/bus/config.hpp"
#include "navbus/bus/key_reader.hpp"
#include "navbus/core/math/units.hpp"

namespace navbus::importers {

namespace {

constexpr bus::Range kAnySeconds{-1e6, 1e6};
constexpr bus::Range kColumns{0, 1000};

std::filesystem::path besideYaml(const std::filesystem::path& yaml, const std::string& file) {
  const std::filesystem::path p(file);
  return (p.is_absolute() ? p : yaml.parent_path() / p).lexically_normal();
}

std::filesystem::path requiredFile(const bus::KeyReader& r, const char* key,
                                   const std::filesystem::path& yaml) {
  if (!r.present(key)) throw bus::ConfigError("data set " + r.path(key) + " is missing");
  const auto path = besideYaml(yaml, r.node()[key].as<std::string>());
  if (!std::filesystem::is_regular_file(path))
    throw bus::ConfigError("data set " + r.path(key) + " = '" + path.string() + "': no such file");
  return path;
}

template <std::size_t N>
void columns(bus::KeyReader& r, const char* key, std::array<std::size_t, N>& out) {
  if (!r.present(key)) {
    r.nested({key});
    return;
  }
  std::vector<double> v;
  r.value(key, v);
  if (v.size() != N)
    throw bus::ConfigError("data set " + r.path(key) + " needs " + std::to_string(N) +
                           " column numbers, has " + std::to_string(v.size()));
  for (std::size_t i = 0; i < N; ++i) {
    if (v[i] < kColumns.lo || v[i] > kColumns.hi ||
        v[i] != static_cast<double>(static_cast<std::size_t>(v[i])))
      throw bus::ConfigError("data set " + r.path(key) + "[" + std::to_string(i) +
                             "] = " + std::to_string(v[i]) + " is not a column number 0..1000");
    out[i] = static_cast<std::size_t>(v[i]);
  }
}

ImuCsvDescription imu(const YAML::Node& node, const std::filesystem::path& yaml) {
  ImuCsvDescription d;
  bus::KeyReader r(node, "imu");
  d.file = requiredFile(r, "file", yaml);
  r.nested({"file"});
  r.integer("sensor_id", d.sensor_id, {0, 4294967295.0})
      .integer("header_lines", d.header_lines, {0, 1e6})
      .integer("time_column", d.time_column, kColumns)
      .number("sample_rate_hz", d.sample_rate_hz, {1.0, 1e5})
      .number("time_offset_s", d.time_offset_s, kAnySeconds)
      .number("block_s", d.block_s, {1e-3, 1.0});
  columns(r, "accel_columns", d.accel_columns);
  columns(r, "gyro_columns", d.gyro_columns);
  r.choice("accel_unit", d.accel_to_mps2,
           {{"g", units::kStandardGravity}, {"mg", units::kMilliG}, {"mps2", 1.0}});
  r.choice("gyro_unit", d.gyro_to_radps, {{"deg_per_s", units::kDeg}, {"rad_per_s", 1.0}});
  r.choice("time_source", d.time_source,
           {{"device_ticks", ImuTimeSource::kDeviceTicks},
            {"gps_seconds_of_week", ImuTimeSource::kGpsSecondsOfWeek},
            {"gps_seconds", ImuTimeSource::kGpsSeconds}});
  r.number("tick_s", d.tick_s, {1e-9, 1.0}).integer("gps_week", d.gps_week, {0, 1e5});
  if (d.time_source == ImuTimeSource::kDeviceTicks) {
    d.time_tag = requiredFile(r, "time_tag", yaml);
    r.nested({"time_tag"});
  } else if (d.time_source == ImuTimeSource::kGpsSecondsOfWeek && d.gps_week == 0) {
    throw bus::ConfigError("data set imu.gps_week is missing (time_source gps_seconds_of_week)");
  }
  if (d.sample_rate_hz == 0.0) throw bus::ConfigError("data set imu.sample_rate_hz is missing");
  r.finish({"time_tag"});
  return d;
}

QualityUse quality(const YAML::Node& node, const std::string& where) {
  QualityUse q;
  bus::KeyReader r(node, where);
  r.value("use", q.use)
      .number("sigma_scale", q.sigma_scale, {1e-3, 1e6})
      .number("min_position_sigma_m", q.min_position_sigma_m, {0.0, 1e6})
      .number("min_velocity_sigma_mps", q.min_velocity_sigma_mps, {0.0, 1e6});
  r.finish();
  return q;
}

PosDescription pos(const YAML::Node& node, const std::filesystem::path& yaml) {
  PosDescription d;
  bus::KeyReader r(node, "gnss_solutions");
  d.file = requiredFile(r, "file", yaml);
  r.nested({"file"});
  r.integer("receiver_id", d.receiver_id, {0, 4294967295.0})
      .number("time_offset_s", d.time_offset_s, kAnySeconds)
      .number("velocity_sigma_when_absent_mps", d.velocity_sigma_when_absent_mps, {0.0, 1e6});
  enum class Height { kEllipsoid, kMsl } height = Height::kEllipsoid;
  r.choice("height", height, {{"ellipsoid", Height::kEllipsoid}, {"msl", Height::kMsl}});
  double separation_m = 0.0;
  r.number("geoid_separation_m", separation_m, {-150.0, 150.0});
  if (height == Height::kMsl) {
    if (!r.present("geoid_separation_m"))
      throw bus::ConfigError(
          "data set gnss_solutions.geoid_separation_m is missing (height: msl needs the geoid "
          "separation N at the site: h = H + N)");
    d.height_to_ellipsoid_m = separation_m;
  } else if (r.present("geoid_separation_m")) {
    throw bus::ConfigError(
        "data set gnss_solutions.geoid_separation_m is set but height is ellipsoid");
  }
  const YAML::Node q = node["quality"];
  if (q) {
    bus::checkKeys(q, "gnss_solutions.quality", {"fix", "float", "sbas", "dgps", "single", "ppp"});
    for (std::size_t i = 1; i < kQualityNames.size(); ++i)
      d.quality[i] =
          quality(q[kQualityNames[i]], std::string("gnss_solutions.quality.") + kQualityNames[i]);
  }
  r.finish({"quality"});
  return d;
}

RinexDescription rinex(const YAML::Node& node, const std::filesystem::path& yaml) {
  RinexDescription d;
  bus::KeyReader r(node, "gnss_observations");
  d.obs = requiredFile(r, "obs", yaml);
  d.nav = requiredFile(r, "nav", yaml);
  r.nested({"obs", "nav"});
  double mask_deg = 0.0;
  r.integer("receiver_id", d.receiver_id, {0, 4294967295.0})
      .value("range_type", d.range_type)
      .value("doppler_type", d.doppler_type)
      .value("cn0_type", d.cn0_type)
      .number("rate_sigma_mps", d.rate_sigma_mps, {1e-4, 1e3})
      .number("range_sigma_scale", d.range_sigma_scale, {1e-3, 1e3})
      .number("min_range_sigma_m", d.min_range_sigma_m, {0.0, 1e4})
      .number("elevation_mask_deg", mask_deg, {0.0, 90.0})
      .number("time_offset_s", d.time_offset_s, kAnySeconds);
  d.elevation_mask_rad = mask_deg * units::kDeg;
  r.finish();
  return d;
}

}  // namespace

DatasetDescription readDatasetDescription(const std::filesystem::path& yaml_file) {
  const YAML::Node root = bus::loadYamlFile(yaml_file.string());
  DatasetDescription d;
  d.file = yaml_file;
  bus::KeyReader r(root, "");
  r.value("name", d.name);
  if (root["imu"]) d.imu = imu(root["imu"], yaml_file);
  if (root["gnss_solutions"]) d.gnss_solutions = pos(root["gnss_solutions"], yaml_file);
  if (root["gnss_observations"]) d.gnss_observations = rinex(root["gnss_observations"], yaml_file);
  if (!d.imu && !d.gnss_solutions && !d.gnss_observations)
    throw bus::ConfigError("data set " + yaml_file.string() +
                           ": nothing to import (no imu, gnss_solutions or gnss_observations)");
  r.finish({"imu", "gnss_solutions", "gnss_observations"});
  return d;
}

}  // namespace navbus::importers
