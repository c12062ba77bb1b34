#include "navbus/importers/imu_csv.hpp"

#include <charconv>
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "navbus/bus/config.hpp"
#include "navbus/core/gnss/gps_broadcast_ephemeris.hpp"
#include "navbus/importers/rtklib_time_tag.hpp"
#include "navbus/records/csv_table.hpp"

namespace navbus::importers {

namespace {

using core::gps::kSecondsPerWeek;
/// A device clock that disagrees with the time tag's span by more than this is another log's.
constexpr double kMaxClockRateError = 0.01;

/// One line's numbers in file units, before the time is mapped.
struct RawSample {
  std::size_t line;
  std::array<double, 3> accel;
  std::array<double, 3> gyro;
  double time;
};

const char* kAccelNames[3] = {"accel x", "accel y", "accel z"};
const char* kGyroNames[3] = {"gyro x", "gyro y", "gyro z"};

std::optional<double> number(const std::string& text) {
  double v = 0.0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (ec != std::errc() || ptr != end || !std::isfinite(v)) return std::nullopt;
  return v;
}

/// The sample of a row, or why it is not one (the column's name and the text).
std::optional<RawSample> parse(const records::CsvRow& row, const ImuCsvDescription& d,
                               std::string& why) {
  auto cell = [&](std::size_t column, const char* name, double& out) {
    if (column >= row.cells.size()) {
      why = fmt::format("{} cells, no column {} ({})", row.cells.size(), column, name);
      return false;
    }
    const std::optional<double> v = number(row.cells[column]);
    if (!v) {
      why = fmt::format("column {} ({}): '{}' is not a number", column, name, row.cells[column]);
      return false;
    }
    out = *v;
    return true;
  };
  RawSample s{row.line, {}, {}, 0.0};
  for (int i = 0; i < 3; ++i) {
    if (!cell(d.accel_columns[i], kAccelNames[i], s.accel[i])) return std::nullopt;
    if (!cell(d.gyro_columns[i], kGyroNames[i], s.gyro[i])) return std::nullopt;
  }
  if (!cell(d.time_column, "time", s.time)) return std::nullopt;
  return s;
}

/// GPS time [ns] of each raw sample's time column.
std::vector<std::int64_t> gpsTimes(const std::vector<RawSample>& raw, const ImuCsvDescription& d,
                                   std::vector<std::string>& notes) {
  std::vector<std::int64_t> out;
  out.reserve(raw.size());
  const auto offset_ns = static_cast<double>(std::llround(d.time_offset_s * 1e9));
  switch (d.time_source) {
    case ImuTimeSource::kGpsSeconds:
      for (const auto& s : raw) out.push_back(std::llround(s.time * 1e9 + offset_ns));
      break;
    case ImuTimeSource::kGpsSecondsOfWeek:
      for (const auto& s : raw)
        out.push_back(std::llround((d.gps_week * kSecondsPerWeek + s.time) * 1e9 + offset_ns));
      break;
    case ImuTimeSource::kDeviceTicks: {
      // The device ticks of the first and last samples map linearly onto the logger's span
      // [start, start + last tick] (RTKLIB demo5's processing of such logs).
      const TimeTag tag = readTimeTag(d.time_tag);
      const double ticks = raw.back().time - raw.front().time;
      const double span_ns = 1e6 * tag.lastTickMs();
      const double device_span_ns = ticks * d.tick_s * 1e9;
      const double rate_error = device_span_ns / span_ns - 1.0;
      if (!(std::abs(rate_error) <= kMaxClockRateError))
        throw bus::ConfigError(fmt::format(
            "{}: the device clock spans {:.3f} s, its time tag {} {:.3f} s: not the same log",
            d.file.string(), 1e-9 * device_span_ns, d.time_tag.string(), 1e-9 * span_ns));
      notes.push_back(fmt::format(
          "{}: device ticks {} .. {} mapped onto the time tag's {:.3f} s from GPS {:.3f} s (the "
          "device clock runs {:+.0f} ppm against the logger's), then {:+.3f} s",
          d.file.filename().string(), raw.front().time, raw.back().time, 1e-9 * span_ns,
          1e-9 * static_cast<double>(tag.start_gps_ns), 1e6 * rate_error, d.time_offset_s));
      const double ns_per_tick = span_ns / ticks;
      for (const auto& s : raw)
        out.push_back(tag.start_gps_ns +
                      std::llround((s.time - raw.front().time) * ns_per_tick + offset_ns));
      break;
    }
  }
  return out;
}

}  // namespace

ImuLog readImuCsv(const ImuCsvDescription& d) {
  const std::vector<records::CsvRow> rows = records::readCsvRows(d.file);
  ImuLog log;
  std::vector<RawSample> raw;
  raw.reserve(rows.size());
  const std::size_t first = d.header_lines;
  for (std::size_t i = first; i < rows.size(); ++i) {
    std::string why;
    if (auto s = parse(rows[i], d, why)) {
      raw.push_back(*s);
      continue;
    }
    const std::string where = fmt::format("{} line {}", d.file.string(), rows[i].line);
    if (i != first && i + 1 != rows.size()) throw bus::ConfigError(where + ": " + why);
    log.skipped.push_back(where + " skipped, cut at the " + (i == first ? "start" : "end") +
                          " of the log: " + why);
  }
  if (raw.size() < 2)
    throw bus::ConfigError(d.file.string() + ": fewer than two samples, no interval to integrate");
  for (std::size_t i = 1; i < raw.size(); ++i) {
    if (!(raw[i].time > raw[i - 1].time))
      throw bus::ConfigError(
          fmt::format("{} line {}: column {} (time): {} is not after line "
                      "{}'s {}",
                      d.file.string(), raw[i].line, d.time_column, raw[i].time, raw[i - 1].line,
                      raw[i - 1].time));
  }
  const std::vector<std::int64_t> times = gpsTimes(raw, d, log.notes);
  log.samples.reserve(raw.size());
  for (std::size_t i = 0; i < raw.size(); ++i) {
    ImuSample s;
    s.time_gps_ns = times[i];
    for (int k = 0; k < 3; ++k) {
      s.specific_force_s_mps2[k] = raw[i].accel[k] * d.accel_to_mps2;
      s.rate_s_radps[k] = raw[i].gyro[k] * d.gyro_to_radps;
    }
    log.samples.push_back(s);
  }
  return log;
}

}  // namespace navbus::importers
