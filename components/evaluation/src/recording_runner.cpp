#include "navbus/evaluation/recording_runner.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <variant>

#include <fmt/format.h>
#include <navbus_idl/GnssPubSubTypes.h>
#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/StarTrackerPubSubTypes.h>

#include "navbus/bus/app.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/core/gnss/gps_broadcast_ephemeris.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/core/math/units.hpp"
#include "navbus/fault_manager/fault_pipeline.hpp"
#include "navbus/importers/importer.hpp"
#include "navbus/nav_filter/lane_set.hpp"
#include "navbus/records/csv_messages.hpp"
#include "navbus/records/formatters.hpp"
#include "navbus/records/mcap.hpp"
#include "navbus/records/mcap_samples.hpp"
#include "navbus/records/recording_layout.hpp"

namespace navbus::evaluation {

namespace {

using Sample =
    std::variant<navbus::ImuIncrement, navbus::ImuIncrementBlock, navbus::ImuRawBlock,
                 navbus::GnssObservationEpoch, navbus::GnssFix, navbus::StarTrackerAttitude>;

/// One recorded sample in the merged order: by data time, then by topic (IMU first, as the
/// filter's merge ranks them), then by sensor (the units of a redundant set in their ids'
/// order, whichever the recorder received first), then file order.
struct Event {
  std::int64_t time_ns;
  int rank;
  std::uint32_t sensor_id;
  std::size_t index;
  Sample sample;
};

/// A recording's sensor samples: a directory of CSV files, or one MCAP file (read once; a file
/// cut short is read up to its last complete record, and `inputs` says what was lost).
class RecordedSamples {
 public:
  RecordedSamples(const std::filesystem::path& path, std::string& inputs)
      : path_(path), inputs_(inputs) {
    if (!std::filesystem::is_regular_file(path)) return;
    if (!records::isMcapFile(path)) {
      throw bus::ConfigError(path.string() +
                             ": neither a directory of CSV files nor an MCAP file (no MCAP magic)");
    }
    mcap_ = records::readMcap(path);
    if (mcap_->cut) inputs_ += records::describeCut(path, *mcap_->cut) + "\n";
  }

  template <class PubSubType>
  void load(const char* topic, int rank, std::vector<Event>& out) {
    using T = typename PubSubType::type;
    std::vector<T> messages;
    std::string from;
    if (mcap_) {
      const records::McapChannel* channel = records::channelOfTopic(*mcap_, topic);
      if (channel == nullptr) return;
      messages = records::decodeChannel<PubSubType>(path_.string(), *mcap_, *channel);
      from = fmt::format("{} channel {}", path_.string(), channel->topic);
    } else {
      const std::filesystem::path file = path_ / records::recordFileName(topic);
      if (!std::filesystem::exists(file)) return;
      const records::CsvTable table = records::readCsv(file);
      messages = records::parseMessages<T>(table, records::messageRowRanges(table));
      from = file.string();
    }
    for (const T& m : messages) add(m, rank, out);
    inputs_ += fmt::format("{}: {} samples\n", from, messages.size());
  }

 private:
  /// A fast-pacing block of epochs, fixes or attitudes goes in as its elements, each one
  /// sample of its own topic at its own time (the filter takes them so); a block of increments
  /// as one sample at its newest increment's time.
  template <class T>
  static void add(const T& m, int rank, std::vector<Event>& out) {
    if constexpr (bus::kIsSensorBlock<T>) {
      for (const auto& element : bus::SensorBlock<T>::elements(m)) add(element, rank, out);
    } else {
      using Traits = bus::SensorMessage<T>;
      out.push_back({static_cast<std::int64_t>(Traits::timeGpsNs(m)), rank, Traits::sensorId(m),
                     out.size(), m});
    }
  }

  std::filesystem::path path_;
  std::string& inputs_;
  std::optional<records::McapContents> mcap_;
};

}  // namespace

ImportedRun importForRun(const std::string& dataset_yaml, const std::string& filter_yaml,
                         const std::filesystem::path& out_dir) {
  const importers::DatasetDescription dataset = importers::readDatasetDescription(dataset_yaml);
  ImportedRun run;
  run.import_text = importers::importDataset(dataset, out_dir / "recording").text;
  run.setup.dir = out_dir / "recording";
  run.setup.filter = bus::parseFile(filter_yaml, nav_filter::parseFilterConfig);
  return run;
}

namespace {

/// The recording's sensor samples in the merged order; raw IMU blocks only when the fault
/// manager's dither monitor reads them.
std::vector<Event> loadEvents(const RecordingSetup& setup, RecordingResult& result) {
  std::vector<Event> events;
  RecordedSamples recorded(setup.dir, result.inputs);
  recorded.load<navbus::ImuIncrementPubSubType>(bus::topic::kImuIncrement, 0, events);
  recorded.load<navbus::ImuIncrementBlockPubSubType>(bus::topic::kImuIncrementBlock, 0, events);
  if (setup.fault_manager && setup.fault_manager->dither.enabled)
    recorded.load<navbus::ImuRawBlockPubSubType>(bus::topic::kImuRaw, 0, events);
  recorded.load<navbus::GnssObservationEpochPubSubType>(bus::topic::kGnssObservations, 1, events);
  recorded.load<navbus::GnssObservationEpochBlockPubSubType>(bus::topic::kGnssObservationsBlock, 1,
                                                             events);
  recorded.load<navbus::GnssFixPubSubType>(bus::topic::kGnssFix, 2, events);
  recorded.load<navbus::GnssFixBlockPubSubType>(bus::topic::kGnssFixBlock, 2, events);
  recorded.load<navbus::StarTrackerAttitudePubSubType>(bus::topic::kStarTracker, 3, events);
  recorded.load<navbus::StarTrackerAttitudeBlockPubSubType>(bus::topic::kStarTrackerBlock, 3,
                                                            events);
  if (events.empty())
    throw bus::ConfigError(
        "no recording of a sensor topic in '" + setup.dir.string() +
        "' (navbus import or navbus record write navbus_imu_increment_block.csv, "
        "navbus_gnss_fix.csv, ...)");
  if (setup.withhold) {
    const auto before = events.size();
    events.erase(std::remove_if(events.begin(), events.end(),
                                [&](const Event& e) {
                                  const auto* fix = std::get_if<navbus::GnssFix>(&e.sample);
                                  return fix != nullptr && setup.withhold(*fix);
                                }),
                 events.end());
    result.fixes_withheld = before - events.size();
  }
  std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) {
    return std::tie(a.time_ns, a.rank, a.sensor_id, a.index) <
           std::tie(b.time_ns, b.rank, b.sensor_id, b.index);
  });
  return events;
}

/// The smoother and the fixes' innovations follow one engine; with lanes the published engine
/// changes at a switch: refused, naming the option (`what`), rather than written wrong or empty.
void refuseWithLanes(const nav_filter::FilterConfig& filter, bool asked, const char* what) {
  if (!asked || filter.lanes.units.empty()) return;
  throw bus::ConfigError(std::string(what) + ": the filter configuration has lanes (" +
                         std::to_string(filter.lanes.units.size()) + " units); it follows one " +
                         "engine, run it on a filter without lanes");
}

/// One recorded sample to the filter's lanes and, as the fault manager's readers take it, to
/// the fault manager's pipeline (its parity test reads every increment of every unit, its
/// dither monitor the raw blocks, its cross-receiver test every receiver's epochs).
void feed(const Sample& sample, nav_filter::LaneSet& filter,
          std::optional<fault_manager::FaultPipeline>& faults) {
  std::visit(
      [&](const auto& m) {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, navbus::ImuIncrement>) {
          filter.onImu(m);
          if (faults) faults->onImuIncrement(m);
        }
        if constexpr (std::is_same_v<T, navbus::ImuIncrementBlock>) {
          filter.onImuBlock(m);
          if (faults)
            for (const navbus::ImuIncrement& increment : m.increments())
              faults->onImuIncrement(increment);
        }
        if constexpr (std::is_same_v<T, navbus::ImuRawBlock>) {
          if (faults) faults->onRawBlock(m);
        }
        if constexpr (std::is_same_v<T, navbus::GnssObservationEpoch>) {
          filter.onGnssObservations(m);
          if (faults) faults->onGnssEpoch(m);
        }
        if constexpr (std::is_same_v<T, navbus::GnssFix>) filter.onGnssFix(m);
        if constexpr (std::is_same_v<T, navbus::StarTrackerAttitude>) filter.onStarTracker(m);
      },
      sample);
}

}  // namespace

RecordingResult runRecording(const RecordingSetup& setup, const RecordedSolutionHook& hook) {
  refuseWithLanes(setup.filter, setup.smooth, "--smooth");
  RecordingResult result;
  const std::vector<Event> events = loadEvents(setup, result);

  bus::HealthCounters health("navbus-offline");
  std::optional<fault_manager::FaultPipeline> faults;
  nav_filter::LaneSet* filter_ptr = nullptr;
  std::vector<navbus::FaultMonitorProgress> progress;  // delivered after each sample, as a reader
  if (setup.fault_manager) {
    faults.emplace(*setup.fault_manager, health,
                   fault_manager::FaultPipeline::Sinks{
                       [&](const navbus::FaultDecision& d) { result.decisions.push_back(d); },
                       [&](const navbus::FilterCommand& c) {
                         result.commands.push_back(c);
                         filter_ptr->onCommand(c);
                       },
                       [&](const navbus::FaultMonitorProgress& p) { progress.push_back(p); }});
  }
  std::function<void(const navbus::FilterDiagnostics&)> on_diagnostics;
  std::function<void(const navbus::FilterCommandOutcome&)> on_outcome;
  if (faults) {
    on_diagnostics = [&](const navbus::FilterDiagnostics& d) {
      result.last_noise_scales = d.noise_scales();
      result.last_process_noise_scale = d.process_noise_scale();
      faults->onDiagnostics(d);
    };
    on_outcome = [&](const navbus::FilterCommandOutcome& o) { faults->onCommandOutcome(o); };
  }
  const bool lanes = !setup.filter.lanes.units.empty();
  core::SmoothingLog smoothing_log;
  core::FixInnovationLog innovation_log;
  nav_filter::FilterConfig filter_config = setup.filter;
  if (setup.smooth) filter_config.engine.smoothing_log = &smoothing_log;
  // One engine's fixes (a lane set would log every lane's into one list).
  if (!lanes) filter_config.engine.fix_innovation_log = &innovation_log;
  std::function<void(const navbus::LaneSolution&)> on_lane;
  if (lanes)
    on_lane = [&](const navbus::LaneSolution& l) {
      result.lane_solutions.push_back(l);
      if (faults) faults->onLaneSolution(l);  // the lanes' word on two suspect units
    };
  nav_filter::LaneSet pipeline(filter_config, health,
                               {{[&](const navbus::NavigationSolution& s) {
                                   ++result.solutions;
                                   if (hook) hook(s);
                                 },
                                 on_diagnostics, nullptr, on_outcome},
                                on_lane});
  filter_ptr = &pipeline;
  for (const Event& e : events) {
    feed(e.sample, pipeline, faults);
    for (const navbus::FaultMonitorProgress& p : progress) pipeline.onFaultMonitorProgress(p);
    progress.clear();
    pipeline.pump(e.time_ns);  // data time bounds the wait for a silent stream
  }
  pipeline.flush(events.back().time_ns);
  result.summary = pipeline.summary();
  result.consistency = pipeline.engine().consistency().counters();
  result.fix_position_nis = pipeline.engine().counters().fix_position_nis;
  result.fix_velocity_nis = pipeline.engine().counters().fix_velocity_nis;
  result.fix_innovations = innovation_log.records();
  if (setup.smooth) {
    std::uint64_t singular = 0;
    result.smoothed = core::smoothFixedInterval(smoothing_log.records(), &singular);
    const auto smoothed = std::count_if(result.smoothed.begin(), result.smoothed.end(),
                                        [](const core::SmoothedEpoch& e) { return e.smoothed; });
    result.smoother_summary = fmt::format(
        "smoother: {} forward records ({} of passes abandoned by a rewind dropped), {} smoothed, "
        "{} where the forward filter restarted or its predicted covariance was singular ({})",
        result.smoothed.size(), smoothing_log.dropped(), smoothed,
        result.smoothed.size() - static_cast<std::size_t>(smoothed), singular);
  }
  if (faults) result.fault_summary = faults->summary();
  return result;
}

void writeSmoothedCsv(const std::filesystem::path& file,
                      const std::vector<core::SmoothedEpoch>& epochs) {
  std::ofstream out(file);
  if (!out) throw bus::ConfigError("cannot write " + file.string());
  out << "gpst_s,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,roll_deg,pitch_deg,"
         "yaw_deg,sigma_n_m,sigma_e_m,sigma_d_m,smoothed\n";
  fmt::memory_buffer buffer;
  constexpr std::int64_t kWeekNs =
      static_cast<std::int64_t>(core::gps::kSecondsPerWeek) * 1'000'000'000;
  for (const core::SmoothedEpoch& e : epochs) {
    const Eigen::Vector3d rpy_deg =
        core::eulerFromDcm(e.state.q_b_to_n.toRotationMatrix()) / units::kDeg;
    const Eigen::Vector3d& v = e.state.vel_ned_mps;
    const auto sd = e.sigma.segment<3>(core::layout::kPos.index);
    fmt::format_to(fmt::appender(buffer),
                   "{:.6f},{:.10f},{:.10f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},"
                   "{:.4f},{:.4f},{}\n",
                   1e-9 * static_cast<double>(e.time_ns % kWeekNs),
                   e.state.position.latitude_rad / units::kDeg,
                   e.state.position.longitude_rad / units::kDeg, e.state.position.height_m, v[0],
                   v[1], v[2], rpy_deg[0], rpy_deg[1], rpy_deg[2], sd[0], sd[1], sd[2],
                   e.smoothed ? 1 : 0);
  }
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  if (!out) throw bus::ConfigError("cannot write " + file.string());
}

void writeFixInnovationsCsv(const std::filesystem::path& file,
                            const std::vector<core::FixInnovation>& fixes) {
  std::ofstream out(file);
  if (!out) throw bus::ConfigError("cannot write " + file.string());
  out << "gpst_s,vel_n_mps,vel_e_mps,vel_d_mps,pos_n_m,pos_e_m,pos_d_m,sigma_pos_n_m,"
         "sigma_pos_e_m,sigma_pos_d_m,vel_inn_n_mps,vel_inn_e_mps,vel_inn_d_mps,"
         "sigma_vel_n_mps,sigma_vel_e_mps,sigma_vel_d_mps,along_track_m,cross_track_m,"
         "consistent\n";
  constexpr double kMinTrackSpeedMps = 1.0;
  constexpr std::int64_t kWeekNs =
      static_cast<std::int64_t>(core::gps::kSecondsPerWeek) * 1'000'000'000;
  fmt::memory_buffer buffer;
  for (const core::FixInnovation& f : fixes) {
    const Eigen::Vector2d v = f.filter_vel_ned_mps.head<2>();
    const double speed = v.norm();
    const Eigen::Vector2d along =
        speed >= kMinTrackSpeedMps ? Eigen::Vector2d(v / speed) : Eigen::Vector2d::Zero();
    const Eigen::Vector2d cross(-along.y(), along.x());  // to the right of the track
    const Eigen::Vector2d p = f.position_m.head<2>();
    fmt::format_to(fmt::appender(buffer), "{:.3f},{:.4f},{:.4f},{:.4f}",
                   1e-9 * static_cast<double>(f.time_ns % kWeekNs), f.filter_vel_ned_mps[0],
                   f.filter_vel_ned_mps[1], f.filter_vel_ned_mps[2]);
    for (const Eigen::Vector3d* row :
         {&f.position_m, &f.position_sigma_m, &f.velocity_mps, &f.velocity_sigma_mps})
      fmt::format_to(fmt::appender(buffer), ",{:.5f},{:.5f},{:.5f}", (*row)[0], (*row)[1],
                     (*row)[2]);
    fmt::format_to(fmt::appender(buffer), ",{:.5f},{:.5f},{}\n", along.dot(p), cross.dot(p),
                   f.consistent ? 1 : 0);
  }
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  if (!out) throw bus::ConfigError("cannot write " + file.string());
}

int runRecordingCommand(const RecordingOptions& o) {
  RecordingSetup setup;
  setup.smooth = o.smooth;
  setup.dir = o.recording;
  setup.filter = bus::parseFile(o.filter, nav_filter::parseFilterConfig);
  refuseWithLanes(setup.filter, o.innovations, "--innovations");
  if (!o.fault_manager.empty())
    setup.fault_manager = bus::parseFile(o.fault_manager, fault_manager::parseFaultManagerConfig);
  std::filesystem::create_directories(o.out_dir);
  const std::string path = o.out_dir + "/solution.csv";
  std::ofstream sol(path);
  if (!sol) throw bus::ConfigError("cannot write " + path);
  sol << records::csvHeader<navbus::NavigationSolution>() << "\n";
  fmt::memory_buffer buffer;
  const RecordingResult r = runRecording(setup, [&](const navbus::NavigationSolution& s) {
    records::appendCsvLine(s, buffer);
    if (buffer.size() > (1u << 20)) {
      sol.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
      buffer.clear();
    }
  });
  sol.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  if (setup.fault_manager) {
    records::writeCsvFile(o.out_dir + "/decisions.csv", r.decisions);
    records::writeCsvFile(o.out_dir + "/commands.csv", r.commands);
  }
  if (!r.lane_solutions.empty()) {
    records::writeCsvFile(o.out_dir + "/lanes.csv", r.lane_solutions);
    std::printf("%zu lane solutions written to %s/lanes.csv\n", r.lane_solutions.size(),
                o.out_dir.c_str());
  }
  std::printf("%s%s\n%s%s%zu solutions written to %s\n", r.inputs.c_str(), r.summary.c_str(),
              r.fault_summary.c_str(), r.fault_summary.empty() ? "" : "\n",
              static_cast<std::size_t>(r.solutions), path.c_str());
  if (o.innovations) {
    writeFixInnovationsCsv(o.out_dir + "/innovations.csv", r.fix_innovations);
    std::printf("%zu fused fixes' innovations written to %s/innovations.csv\n",
                r.fix_innovations.size(), o.out_dir.c_str());
  }
  if (o.smooth) {
    writeSmoothedCsv(o.out_dir + "/smoothed.csv", r.smoothed);
    std::printf("%s\nsmoothed epochs written to %s/smoothed.csv\n", r.smoother_summary.c_str(),
                o.out_dir.c_str());
  }
  return sol ? 0 : bus::kExitConfigError;
}

}  // namespace navbus::evaluation
