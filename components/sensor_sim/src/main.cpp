// navbus-sensor-sim: publishes IMU increments, raw IMU blocks, GNSS observations and fixes, and
// star-tracker attitudes of a simulated vehicle, in real time or as fast as the readers allow.
#include <algorithm>
#include <chrono>
#include <thread>

#include "navbus/bus/app.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/bus/stream_end.hpp"
#include "navbus/sensor_sim/file_writer.hpp"
#include "navbus/sensor_sim/frame_publisher.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"
#include "navbus/sim/scenario_source.hpp"

namespace nb = navbus;

int main(int argc, char** argv) {
  nb::bus::ShutdownSignal shutdown;
  CLI::App app{
      "navbus-sensor-sim: simulated IMU, GNSS and star-tracker streams on the navbus DDS bus",
      "navbus-sensor-sim"};
  nb::bus::CommonOptions common;
  double duration_override = -1.0;
  std::string pacing_override;
  std::string files_dir;
  std::uint64_t seed_override = 0;
  bool seed_given = false;
  nb::bus::addCommonOptions(app, common, false);
  app.add_option("--scenario", common.config_file,
                 "scenario file (same as --config), e.g. scenarios/seed000_aircraft.yaml");
  app.add_option("--files", files_dir,
                 "write the streams as CSV files into this directory instead of publishing");
  app.add_option("--seed", seed_override, "Monte Carlo seed (overrides the scenario's)")
      ->each([&](const std::string&) { seed_given = true; });
  app.add_option("--duration", duration_override, "seconds of data to publish (0: until stopped)")
      ->check(CLI::Range(0.0, 1e7));
  app.add_option("--pacing", pacing_override, "realtime or fast (flow-controlled, nothing lost)")
      ->check(CLI::IsMember({"realtime", "fast"}));
  double block_override = -1.0;
  app.add_option("--fast-pacing-block", block_override,
                 "seconds of each stream's data per DDS sample in fast pacing (overrides "
                 "timing.fast_pacing_block_s; 0: one measurement per sample)")
      ->check(CLI::Range(0.0, 10.0));
  app.footer("Exit codes: 0 done, 1 runtime error, 2 configuration error, 3 DDS error.");

  return nb::bus::runMain(app, argc, argv, common, [&](const YAML::Node& yaml) {
    nb::sensor_sim::SimConfig config = nb::sensor_sim::parseSimConfig(yaml);
    if (duration_override >= 0.0) config.duration_s = duration_override;
    if (!pacing_override.empty()) {
      config.pacing = pacing_override == "fast" ? nb::sensor_sim::Pacing::kFast
                                                : nb::sensor_sim::Pacing::kRealTime;
    }
    if (seed_given) config.scenario.seed = seed_override;
    if (block_override >= 0.0) config.fast_pacing_block_s = block_override;
    auto startNow = [&] {
      // Real GPS time, on a whole IMU period, so that a restarted simulator continues forward.
      const auto now = static_cast<std::int64_t>(nb::bus::gpsTimeNowNs());
      config.scenario.start_time_ns = now - now % config.scenario.imu_period_ns;
    };
    const std::int64_t period_ns = config.scenario.imu_period_ns;
    double duration_s = config.duration_s;
    if (duration_s <= 0.0 && !files_dir.empty()) {
      double segments_s = 0.0;
      for (const auto& seg : config.scenario.segments) segments_s += seg.duration_s;
      if (segments_s <= 0.0) {
        throw nb::bus::ConfigError(
            "--files needs a finite run: set timing.duration_s or --duration");
      }
      duration_s = segments_s;
    }
    const std::int64_t total =
        duration_s > 0.0 ? static_cast<std::int64_t>(
                               std::llround(duration_s * 1e9 / static_cast<double>(period_ns)))
                         : -1;
    if (!files_dir.empty()) {
      // Offline: no DDS participant at all.
      if (config.start_now) startNow();
      nb::sim::ScenarioSource source(config.scenario);
      nb::sensor_sim::FileWriter files(files_dir, config.scenario, config.extra_imu_sensor_ids,
                                       config.extra_gnss_receiver_ids);
      while (!shutdown.requested() && source.index() < total) files.write(source.next());
      const auto& n = files.counts();
      spdlog::info(
          "summary: scenario '{}' seed {}: wrote {} IMU increments, {} raw blocks, {} GNSS epochs, "
          "{} fixes, "
          "{} star-tracker attitudes ({:.3f} s), further IMU units' increments {}, further "
          "receivers' epochs {} to {}",
          config.scenario.name, config.scenario.seed, n.imu, n.raw, n.gnss_epochs, n.gnss_fixes,
          n.star_tracker, static_cast<double>(n.imu) * static_cast<double>(period_ns) * 1e-9,
          n.unit_increments, n.receiver_epochs, files_dir);
      return static_cast<int>(nb::bus::kExitOk);
    }

    nb::bus::Participant participant(nb::bus::participantOptions(common, yaml, "navbus-sensor-sim"),
                                     shutdown);
    nb::sensor_sim::FramePublisher publisher(participant, config);

    using Clock = std::chrono::steady_clock;
    // Reliable delivery starts with matching: wait (bounded) for the readers so that nothing
    // is published before the filter and the fault manager have joined.
    const auto until = Clock::now() + std::chrono::duration<double>(config.wait_for_readers_s);
    while (!participant.stopping() && !publisher.readersMatched() && Clock::now() < until) {
      participant.spinOnce(std::chrono::milliseconds(20));
    }
    if (!publisher.readersMatched()) {
      spdlog::warn(
          "readers not all matched after {} s ({} on the IMU topic, {} wanted); publishing anyway",
          config.wait_for_readers_s, publisher.imuReaders(), config.min_readers.imu);
    } else if (config.wait_for_readers_s > 0.0) {
      participant.spinFor(nb::bus::kStartSettle);  // the readers' side of the match
    }
    if (config.start_now) startNow();  // after the wait: the data starts now
    nb::sim::ScenarioSource source(config.scenario);
    spdlog::info("publishing {} s of data, {} pacing, IMU {} Hz{}, start GPS {} ns",
                 duration_s > 0 ? std::to_string(duration_s) : std::string("unbounded"),
                 config.pacing == nb::sensor_sim::Pacing::kFast ? "fast" : "real-time",
                 1e9 / static_cast<double>(period_ns),
                 publisher.incrementsPerBlock() > 0
                     ? fmt::format(" in blocks of {} increments", publisher.incrementsPerBlock())
                     : std::string(),
                 config.scenario.start_time_ns);
    const std::int64_t spin_every =
        static_cast<std::int64_t>(std::max<std::size_t>(1, publisher.incrementsPerBlock()));
    const auto wall_start = Clock::now();
    while (!participant.stopping() && (total < 0 || source.index() < total)) {
      const nb::sim::SensorFrame frame = source.next();
      if (!publisher.publish(frame)) break;
      if (config.pacing == nb::sensor_sim::Pacing::kRealTime) {
        const auto due = wall_start + std::chrono::nanoseconds(source.index() * period_ns);
        while (!participant.stopping() && Clock::now() < due) {
          participant.spinOnce(
              std::chrono::duration_cast<std::chrono::nanoseconds>(due - Clock::now()));
        }
      } else if (source.index() % spin_every == 0) {
        // Timers and readers, without a waitset round per frame (a syscall and wake-ups that
        // cost more than the frame itself when increments go out in blocks).
        participant.spinOnce(std::chrono::nanoseconds(0));
      }
    }
    // The end of the data is announced (not a loss). Not on SIGTERM: a reader that stopped
    // taking (a full KEEP_ALL history) would hold the dispose's acknowledgment up.
    const bool announce_end = !participant.stopping();
    if (announce_end) {
      publisher.endStreams();
      participant.announceDataEnded();  // also in its health: reliable for every reader
    }
    publisher.flush();
    // From the first write to the last acknowledgment: the bus throughput in fast pacing (not
    // the linger after it, which only keeps the writers on the bus for best-effort readers).
    const double wall_s = std::chrono::duration<double>(Clock::now() - wall_start).count();
    if (announce_end) participant.spinFor(navbus::bus::kEndOfStreamLinger);
    participant.finish();
    const auto& n = publisher.counts();
    // Seconds of data: the increments of one IMU (every unit publishes one per frame).
    const double units = 1.0 + static_cast<double>(config.extra_imu_sensor_ids.size());
    const double data_s =
        static_cast<double>(n.increments) / units * static_cast<double>(period_ns) * 1e-9;
    spdlog::info(
        "summary: published {} IMU increments in {} samples, {} raw samples in {} blocks, {} GNSS "
        "epochs, {} GNSS fixes, {} star-tracker attitudes in {} samples ({:.3f} s of data), {} "
        "write retries",
        n.increments, n.increment_samples, n.raw_samples, n.raw_blocks, n.gnss_epochs, n.gnss_fixes,
        n.star_tracker, n.measurement_samples, data_s, publisher.writeRetries());
    spdlog::info(
        "throughput: {:.3f} s of data in {:.3f} s from the first write to the last "
        "acknowledgment ({:.1f}x real time): {:.0f} samples/s, {:.0f} measurements/s",
        data_s, wall_s, wall_s > 0 ? data_s / wall_s : 0.0,
        wall_s > 0 ? static_cast<double>(n.samples()) / wall_s : 0.0,
        wall_s > 0 ? static_cast<double>(n.measurements()) / wall_s : 0.0);
    return static_cast<int>(nb::bus::kExitOk);
  });
}
