#include "navbus/importers/importer.hpp"

#include <cmath>

#include <fmt/format.h>

#include "navbus/bus/config.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/core/math/units.hpp"
#include "navbus/importers/imu_csv.hpp"
#include "navbus/importers/imu_increments.hpp"
#include "navbus/importers/rtklib_pos.hpp"
#include "navbus/records/formatters.hpp"
#include "navbus/records/recording_layout.hpp"

namespace navbus::importers {

namespace {

template <class T>
void write(const std::filesystem::path& dir, const char* topic, const std::vector<T>& messages,
           std::string& text) {
  const std::filesystem::path path = dir / records::recordFileName(topic);
  if (!records::writeCsvFile(path.string(), messages))
    throw bus::ConfigError(path.string() + ": cannot be written");
  text += fmt::format("wrote {} samples of {} to {}\n", messages.size(), topic, path.string());
}

/// Adds the step to every sample from its onset on; counts the samples changed.
void injectStep(const ImuStep& step, std::vector<ImuSample>& samples, ImportReport& report) {
  if (samples.empty()) return;
  report.imu_step_onset_gps_ns =
      samples.front().time_gps_ns + std::llround(step.onset_after_start_s * 1e9);
  if (report.imu_step_onset_gps_ns > samples.back().time_gps_ns)
    throw bus::ConfigError(fmt::format(
        "IMU step onset {:g} s after the first sample is beyond the log's last sample ({:.3f} s)",
        step.onset_after_start_s,
        1e-9 * static_cast<double>(samples.back().time_gps_ns - samples.front().time_gps_ns)));
  for (ImuSample& s : samples) {
    if (s.time_gps_ns < report.imu_step_onset_gps_ns) continue;
    (step.gyro ? s.rate_s_radps : s.specific_force_s_mps2)[step.axis] += step.step;
    ++report.imu_samples_injected;
  }
}

void importImu(const ImuCsvDescription& d, const std::filesystem::path& out_dir,
               ImportReport& report) {
  ImuLog log = readImuCsv(d);
  for (const auto& s : log.skipped) report.text += s + "\n";
  for (const auto& s : log.notes) report.text += s + "\n";
  if (d.step) injectStep(*d.step, log.samples, report);
  const auto increments = incrementsFromSamples(log.samples, d.sensor_id);
  const auto blocks = blocksOf(increments, d.block_s);
  report.imu_samples = log.samples.size();
  report.imu_increments = increments.size();
  report.imu_blocks = blocks.size();
  const double span_s =
      1e-9 * static_cast<double>(log.samples.back().time_gps_ns - log.samples.front().time_gps_ns);
  report.text += fmt::format(
      "{}: {} samples over {:.3f} s ({:.1f} Hz, nominal {:g} Hz) -> {} increments (trapezoidal) "
      "in {} blocks\n",
      d.file.string(), log.samples.size(), span_s, static_cast<double>(increments.size()) / span_s,
      d.sample_rate_hz, increments.size(), blocks.size());
  if (d.step)
    report.text += fmt::format(
        "injected: {} step of {:g} {} on sensor axis {} from {:g} s after the first sample ({} "
        "samples changed)\n",
        d.step->gyro ? "a gyro" : "an accelerometer",
        d.step->gyro ? d.step->step / units::kDeg : d.step->step, d.step->gyro ? "deg/s" : "m/s^2",
        "xyz"[d.step->axis], d.step->onset_after_start_s, report.imu_samples_injected);
  write(out_dir, bus::topic::kImuIncrementBlock, blocks, report.text);
}

void importSolutions(const PosDescription& d, const std::filesystem::path& out_dir,
                     ImportReport& report) {
  const PosLog log = readPosFile(d);
  report.gnss_fixes = log.fixes.size();
  std::string qualities;
  for (std::size_t q = 1; q < kQualityNames.size(); ++q) {
    if (log.epochs_by_quality[q] == 0) continue;
    qualities += fmt::format("{}{} {}", qualities.empty() ? "" : ", ", kQualityNames[q],
                             log.epochs_by_quality[q]);
    if (log.left_out_by_quality[q] > 0)
      qualities += fmt::format(" ({} left out)", log.left_out_by_quality[q]);
  }
  report.text +=
      fmt::format("{}: epochs {}; {} fixes{}\n", d.file.string(), qualities, log.fixes.size(),
                  log.has_velocity ? "" : ", no velocity columns: position only");
  write(out_dir, bus::topic::kGnssFix, log.fixes, report.text);
}

void importObservations(const RinexDescription& d, const std::filesystem::path& out_dir,
                        ImportReport& report) {
  const ObservationLog log = readRinexObservations(d);
  std::size_t measurements = 0;
  for (const auto& e : log.epochs) measurements += e.satellites().size();
  report.gnss_epochs = log.epochs.size();
  report.text += fmt::format(
      "{}: {} epochs read, {} written with {} satellite measurements; left out: {} epochs before "
      "a first position to place the satellites from, {} of other systems, {} without {}, {} "
      "without ephemeris, {} below the mask, {} out of range; {} without {} (no rate)\n",
      d.obs.string(), log.epochs_read, log.epochs.size(), measurements, log.epochs_unplaced,
      log.other_systems, log.missing_range, d.range_type, log.no_ephemeris, log.below_mask,
      log.bad_range, log.no_doppler, d.doppler_type);
  if (!log.has_iono)
    report.text += fmt::format(
        "{}: no ionosphere parameters (ION ALPHA/BETA): only the model's constant night-time "
        "delay is removed\n",
        d.nav.string());
  if (d.ramp)
    report.text += fmt::format(
        "injected: {:g} m/s into G{:02d}'s pseudoranges from {:g} s after the first epoch "
        "({} pseudoranges changed)\n",
        d.ramp->rate_mps, d.ramp->sv_id, d.ramp->onset_after_start_s, log.injected);
  write(out_dir, bus::topic::kGnssObservations, log.epochs, report.text);
}

}  // namespace

ImportReport importDataset(const DatasetDescription& dataset,
                           const std::filesystem::path& out_dir) {
  std::filesystem::create_directories(out_dir);
  ImportReport report;
  if (dataset.imu) importImu(*dataset.imu, out_dir, report);
  if (dataset.gnss_solutions) importSolutions(*dataset.gnss_solutions, out_dir, report);
  if (dataset.gnss_observations) importObservations(*dataset.gnss_observations, out_dir, report);
  return report;
}

}  // namespace navbus::importers
