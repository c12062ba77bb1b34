#include "navbus/importers/rtklib_pos.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>

#include <fmt/format.h>

#include "navbus/bus/config.hpp"
#include "navbus/core/gnss/gps_broadcast_ephemeris.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/core/math/units.hpp"
#include "navbus/gnss_data/rinex2.hpp"

namespace navbus::importers {

namespace {

using core::gps::kSecondsPerWeek;

/// Where each value is in a data line's whitespace-separated tokens (the time takes two).
struct Columns {
  int lat{-1}, lon{-1}, height{-1}, q{-1}, ns{-1}, sdn{-1}, sde{-1}, sdu{-1};
  int vn{-1}, ve{-1}, vu{-1}, sdvn{-1}, sdve{-1}, sdvu{-1};
  bool calendar_time{true};  ///< "yyyy/mm/dd hh:mm:ss.sss", else "week seconds"
};

std::vector<std::string> tokens(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string t; in >> t;) out.push_back(t);
  return out;
}

/// Column positions from the last `%` header line, e.g. "%  GPST  latitude(deg) ...".
Columns columnsOf(const std::string& header, const std::string& file) {
  std::vector<std::string> names = tokens(header.substr(1));
  if (names.empty() || names[0] != "GPST")
    throw bus::ConfigError(file + ": the header's time column is '" +
                           (names.empty() ? std::string() : names[0]) +
                           "', navbus reads GPST time stamps (RTKLIB: out-timesys = gpst)");
  Columns c;
  auto at = [&](const char* name) {
    for (std::size_t i = 1; i < names.size(); ++i)
      if (names[i] == name) return static_cast<int>(i) + 1;  // the time takes two tokens
    return -1;
  };
  c.lat = at("latitude(deg)");
  c.lon = at("longitude(deg)");
  c.height = at("height(m)");
  c.q = at("Q");
  c.ns = at("ns");
  c.sdn = at("sdn(m)");
  c.sde = at("sde(m)");
  c.sdu = at("sdu(m)");
  if (c.lat < 0 || c.lon < 0 || c.height < 0 || c.q < 0 || c.ns < 0 || c.sdn < 0 || c.sde < 0 ||
      c.sdu < 0)
    throw bus::ConfigError(file +
                           ": the header has no latitude(deg), longitude(deg), height(m), "
                           "Q, ns, sdn(m), sde(m), sdu(m) (RTKLIB: out-solformat = llh, "
                           "out-degformat = deg)");
  c.vn = at("vn(m/s)");
  c.ve = at("ve(m/s)");
  c.vu = at("vu(m/s)");
  c.sdvn = at("sdvn");
  c.sdve = at("sdve");
  c.sdvu = at("sdvu");
  return c;
}

class LineReader {
 public:
  LineReader(const std::string& file, std::size_t line, std::vector<std::string> t)
      : file_(file), line_(line), t_(std::move(t)) {}
  double number(int index, const char* name) const {
    if (index >= static_cast<int>(t_.size()))
      throw error(fmt::format("{} fields, no {}", t_.size(), name));
    double v = 0.0;
    const std::string& s = t_[index];
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || ptr != s.data() + s.size() || !std::isfinite(v))
      throw error(fmt::format("{}: '{}' is not a number", name, s));
    return v;
  }
  /// GPS time of the epoch [ns].
  std::int64_t timeNs(bool calendar) const {
    if (t_.size() < 2) throw error("no time stamp");
    if (!calendar) {
      const double week = number(0, "GPS week");
      const double sow = number(1, "GPS seconds of week");
      return std::llround(week * kSecondsPerWeek * 1e9 + sow * 1e9);
    }
    int y = 0, mo = 0, d = 0, h = 0, mi = 0;
    char s1 = 0, s2 = 0, c1 = 0, c2 = 0;
    double sec = 0.0;
    std::istringstream date(t_[0]), time(t_[1]);
    if (!(date >> y >> s1 >> mo >> s2 >> d) || s1 != '/' || s2 != '/' || mo < 1 || mo > 12 ||
        d < 1 || d > 31)
      throw error(fmt::format("date: '{}' is not yyyy/mm/dd", t_[0]));
    if (!(time >> h >> c1 >> mi >> c2 >> sec) || c1 != ':' || c2 != ':' || h > 23 || mi > 59 ||
        !(sec >= 0.0 && sec < 61.0))
      throw error(fmt::format("time: '{}' is not hh:mm:ss.sss", t_[1]));
    const double whole = gnss_data::gpsSecondsFromCalendar(y, mo, d, h, mi, 0.0);
    return std::llround(whole) * 1'000'000'000 + std::llround(sec * 1e9);
  }
  bus::ConfigError error(const std::string& what) const {
    return bus::ConfigError(fmt::format("{} line {}: {}", file_, line_, what));
  }

 private:
  const std::string& file_;
  std::size_t line_;
  std::vector<std::string> t_;
};

double sigma(double file_sigma, double scale, double floor) {
  return std::max(file_sigma * scale, floor);
}

}  // namespace

PosLog readPosFile(const PosDescription& d) {
  const std::string file = d.file.string();
  std::ifstream in(d.file);
  if (!in) throw bus::ConfigError(file + ": cannot be read");
  PosLog log;
  std::optional<Columns> columns;
  std::string header;
  std::string text;
  const auto offset_ns = std::llround(d.time_offset_s * 1e9);
  for (std::size_t line = 1; std::getline(in, text); ++line) {
    if (text.empty()) continue;
    if (text[0] == '%') {
      header = text;
      continue;
    }
    if (!columns) {
      if (header.empty()) throw bus::ConfigError(file + ": no '%' header line before the data");
      columns = columnsOf(header, file);
      log.has_velocity = columns->vn >= 0 && columns->ve >= 0 && columns->vu >= 0 &&
                         columns->sdvn >= 0 && columns->sdve >= 0 && columns->sdvu >= 0;
      columns->calendar_time = text.find('/') != std::string::npos;
    }
    const Columns& c = *columns;
    const LineReader r(file, line, tokens(text));
    const double q = r.number(c.q, "Q");
    if (q != std::floor(q) || q < 1 || q >= static_cast<double>(kQualityNames.size()))
      throw r.error(fmt::format("Q: {} is not an RTKLIB quality 1..6", q));
    const auto quality = static_cast<std::size_t>(q);
    ++log.epochs_by_quality[quality];
    const QualityUse& use = d.quality[quality];
    if (!use.use) {
      ++log.left_out_by_quality[quality];
      continue;
    }
    const core::earth::Geodetic position{r.number(c.lat, "latitude(deg)") * units::kDeg,
                                         r.number(c.lon, "longitude(deg)") * units::kDeg,
                                         r.number(c.height, "height(m)") + d.height_to_ellipsoid_m};
    if (std::abs(position.latitude_rad) > M_PI / 2 || std::abs(position.longitude_rad) > M_PI)
      throw r.error("latitude or longitude out of range");
    navbus::GnssFix fix;
    fix.receiver_id(d.receiver_id);
    fix.seq(log.fixes.size() + 1);
    fix.time_gps_ns(static_cast<std::uint64_t>(r.timeNs(c.calendar_time) + offset_ns));
    fix.latitude_rad(position.latitude_rad);
    fix.longitude_rad(position.longitude_rad);
    fix.height_m(position.height_m);
    const Eigen::Vector3d ecef = core::earth::geodeticToEcef(position);
    fix.pos_ecef_m({ecef.x(), ecef.y(), ecef.z()});
    fix.pos_sigma_ned_m(
        {sigma(r.number(c.sdn, "sdn(m)"), use.sigma_scale, use.min_position_sigma_m),
         sigma(r.number(c.sde, "sde(m)"), use.sigma_scale, use.min_position_sigma_m),
         sigma(r.number(c.sdu, "sdu(m)"), use.sigma_scale, use.min_position_sigma_m)});
    if (log.has_velocity) {
      fix.vel_ned_mps(
          {r.number(c.vn, "vn(m/s)"), r.number(c.ve, "ve(m/s)"), -r.number(c.vu, "vu(m/s)")});
      fix.vel_sigma_ned_mps(
          {sigma(r.number(c.sdvn, "sdvn"), use.sigma_scale, use.min_velocity_sigma_mps),
           sigma(r.number(c.sdve, "sdve"), use.sigma_scale, use.min_velocity_sigma_mps),
           sigma(r.number(c.sdvu, "sdvu"), use.sigma_scale, use.min_velocity_sigma_mps)});
    } else {
      const double s = d.velocity_sigma_when_absent_mps;
      fix.vel_ned_mps({0.0, 0.0, 0.0});
      fix.vel_sigma_ned_mps({s, s, s});
    }
    const double ns = r.number(c.ns, "ns");
    if (ns < 0 || ns > 255 || ns != std::floor(ns))
      throw r.error(fmt::format("ns: {} is not a satellite count", ns));
    fix.num_satellites_used(static_cast<std::uint16_t>(ns));
    fix.valid(true);
    if (!log.fixes.empty() && fix.time_gps_ns() <= log.fixes.back().time_gps_ns())
      throw r.error("time stamp not after the previous epoch's");
    log.fixes.push_back(fix);
    log.quality.push_back(static_cast<std::uint8_t>(quality));
  }
  if (!columns) throw bus::ConfigError(file + ": no solution epochs");
  return log;
}

}  // namespace navbus::importers
