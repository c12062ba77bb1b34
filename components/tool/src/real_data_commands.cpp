// Real logs, offline (no DDS participant): `navbus allan` reads a recorded IMU's noise densities
// from its standing start; `navbus import` turns a user's logs, described by a
// data set YAML, into a navbus recording (components/importers); `navbus benchmark real-car`
// scores the filter on one with GNSS outages (evaluation/real_car_benchmark.hpp).
#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>

#include <fmt/format.h>

#include "navbus/bus/config.hpp"
#include "navbus/core/math/units.hpp"

#include "navbus/evaluation/imu_noise_survey.hpp"
#include "navbus/evaluation/mounting_calibration.hpp"
#include "navbus/evaluation/real_car_benchmark.hpp"
#include "navbus/evaluation/time_offset_calibration.hpp"
#include "navbus/importers/importer.hpp"
#include "subcommand.hpp"

namespace navbus::tool::cli {
namespace {

/// --accel-step / --gyro-step AXIS,STEP,ONSET: an IMU bias step injected by the import.
struct ImuStepOptions {
  std::vector<double> accel, gyro;

  void add(CLI::App& app) {
    CLI::Option* a =
        app.add_option("--accel-step", accel,
                       "AXIS,STEP,ONSET: add STEP [m/s^2] to the accelerometer's sensor axis AXIS "
                       "(0 x, 1 y, 2 z of the file's columns) from ONSET [s after the first IMU "
                       "sample] (a fault for the detectors to find)")
            ->expected(3)
            ->delimiter(',');
    app.add_option("--gyro-step", gyro, "AXIS,STEP,ONSET: the same for the gyro, STEP in deg/s")
        ->expected(3)
        ->delimiter(',')
        ->excludes(a);
  }

  /// The step in SI, or nullopt; throws bus::ConfigError naming the option and the value.
  std::optional<importers::ImuStep> step() const {
    const bool gyro_step = !gyro.empty();
    const std::vector<double>& v = gyro_step ? gyro : accel;
    if (v.empty()) return std::nullopt;
    if (!(v[0] == 0 || v[0] == 1 || v[0] == 2) || !std::isfinite(v[1]) || !(v[2] >= 0.0))
      throw bus::ConfigError(
          fmt::format("--{}-step {},{},{}: AXIS must be 0, 1 or 2, STEP finite, ONSET >= 0 s",
                      gyro_step ? "gyro" : "accel", v[0], v[1], v[2]));
    return importers::ImuStep{gyro_step, static_cast<int>(v[0]),
                              gyro_step ? v[1] * units::kDeg : v[1], v[2]};
  }
};

class ImportCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.add_subcommand(
        "import",
        "real logs into a navbus recording (for replay and offline): an IMU CSV file with its "
        "clock (RTKLIB time tag), RTKLIB solutions (.pos), as a data set YAML describes them "
        "(config/datasets/)");
    cli_->add_option("dataset", dataset_, "data set YAML")->required()->check(CLI::ExistingFile);
    cli_->add_option("-o,--out", out_dir_, "recording directory (created)")->required();
    cli_->add_option("--ramp", ramp_,
                     "SV,RATE,ONSET: add RATE [m/s] * (t - ONSET) to GPS satellite SV's raw "
                     "pseudoranges from ONSET [s after the first observation epoch] (a fault "
                     "for the GLR to find; needs gnss_observations in the data set)")
        ->expected(3)
        ->delimiter(',');
    imu_step_.add(*cli_);
  }
  bool usesBus() const override { return false; }
  int run(bus::Participant::Options& /*options*/, bus::ShutdownSignal& /*shutdown*/) override {
    auto description = importers::readDatasetDescription(dataset_);
    if (const auto step = imu_step_.step()) {
      if (!description.imu)
        throw bus::ConfigError("--accel-step/--gyro-step: " + dataset_ + " has no imu");
      description.imu->step = step;
    }
    if (!ramp_.empty()) {
      if (!description.gnss_observations)
        throw bus::ConfigError("--ramp: " + dataset_ + " has no gnss_observations to inject into");
      const double sv = ramp_[0];
      if (!(sv >= 1 && sv <= 32 && sv == std::floor(sv)) || !std::isfinite(ramp_[1]) ||
          !(ramp_[2] >= 0.0))
        throw bus::ConfigError(
            fmt::format("--ramp {},{},{}: SV must be a GPS PRN 1..32, RATE finite, ONSET >= 0 s",
                        ramp_[0], ramp_[1], ramp_[2]));
      description.gnss_observations->ramp =
          importers::PseudorangeRamp{static_cast<int>(sv), ramp_[1], ramp_[2]};
    }
    const auto report = importers::importDataset(description, out_dir_);
    std::fputs(report.text.c_str(), stdout);
    return 0;
  }

 private:
  std::string dataset_;
  std::string out_dir_;
  std::vector<double> ramp_;
  ImuStepOptions imu_step_;
};

/// `--outage-schedule LENGTH,PERIOD,FIRST`: a regular schedule instead of an outage list.
CLI::Option* addSchedule(CLI::App& app, std::vector<double>& values) {
  return app
      .add_option("--outage-schedule", values,
                  "LENGTH,PERIOD,FIRST: outages of LENGTH [s] every PERIOD [s] from FIRST [GPS s "
                  "of week] to the log's end (15,45,243298.499 is the shipped drive_0708 list)")
      ->expected(3)
      ->delimiter(',');
}

std::optional<evaluation::OutageSchedule> scheduleOf(const std::vector<double>& v) {
  if (v.empty()) return std::nullopt;
  return evaluation::OutageSchedule{v[0], v[1], v[2]};
}

/// `navbus benchmark`, the parent of the real-log benchmarks (made by the first one added).
CLI::App* benchmarkApp(CLI::App& app) {
  for (CLI::App* existing : app.get_subcommands({})) {
    if (existing->get_name() == "benchmark") return existing;
  }
  CLI::App* benchmark = app.add_subcommand("benchmark", "benchmarks on real logs");
  benchmark->require_subcommand(1);
  return benchmark;
}

/// --fault-manager of the real-log benchmarks: the GLR beside the filter, so that its
/// protection levels are published and scored.
void addFaultManager(CLI::App& app, evaluation::RealCarOptions& o) {
  app.add_option("--fault-manager", o.fault_manager,
                 "navbus-fault-manager YAML (config/fault_manager.yaml): run the fault pipeline "
                 "beside the filter, its decisions acting on it as on the bus (the protection "
                 "levels of a filter with an integrity block are scored either way)")
      ->check(CLI::ExistingFile);
}

class RealCarBenchmarkCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = benchmarkApp(app)->add_subcommand(
        "real-car",
        "a car's log with GNSS outages: the filter runs causally without the GNSS solutions "
        "inside each outage; its antenna positions are scored against the withheld fixed epochs");
    cli_->add_option("dataset", o_.dataset, "data set YAML (config/datasets/drive_0708.yaml)")
        ->required()
        ->check(CLI::ExistingFile);
    cli_->add_option("--filter", o_.filter, "navbus-filter YAML (config/filter_drive_0708.yaml)")
        ->required()
        ->check(CLI::ExistingFile);
    CLI::Option* list =
        cli_->add_option("--outages", o_.outages,
                         "outage list: `START END` per line, GPS seconds of "
                         "week, # comments (config/datasets/drive_0708_outages.txt)")
            ->check(CLI::ExistingFile);
    addSchedule(*cli_, schedule_)->excludes(list);
    cli_->add_option("-o,--out", o_.out_dir,
                     "output directory: solution.csv (antenna, IMU rate), outages.csv, "
                     "scores.csv, the imported recording")
        ->required();
    cli_->add_flag("--smooth", o_.smooth,
                   "also score the fixed-interval (Rauch-Tung-Striebel) smoother over the same "
                   "forward run: smoothed.csv, smoothed_outages.csv");
    addFaultManager(*cli_, o_);
    imu_step_.add(*cli_);
  }
  bool usesBus() const override { return false; }
  int run(bus::Participant::Options& /*options*/, bus::ShutdownSignal& /*shutdown*/) override {
    if (o_.outages.empty() && schedule_.empty())
      throw bus::ConfigError("benchmark real-car needs --outages FILE or --outage-schedule");
    o_.schedule = scheduleOf(schedule_);
    o_.imu_step = imu_step_.step();
    return evaluation::runRealCarBenchmark(o_);
  }

 private:
  evaluation::RealCarOptions o_;
  std::vector<double> schedule_;
  ImuStepOptions imu_step_;
};

class RealDataBenchmarkCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = benchmarkApp(app)->add_subcommand(
        "real-data",
        "any real log with RTK fixes: the filter's antenna positions against the fixed epochs "
        "(with --outages, as real-car), beside single point positioning of the log's own "
        "pseudoranges when the data set has gnss_observations (config/datasets/walk_0827.yaml)");
    cli_->add_option("dataset", o_.dataset, "data set YAML")->required()->check(CLI::ExistingFile);
    cli_->add_option("--filter", o_.filter, "navbus-filter YAML (config/filter_walk_0827_tc.yaml)")
        ->required()
        ->check(CLI::ExistingFile);
    CLI::Option* list = cli_->add_option("--outages", o_.outages, "outage list (optional)")
                            ->check(CLI::ExistingFile);
    addSchedule(*cli_, schedule_)->excludes(list);
    cli_->add_option("-o,--out", o_.out_dir,
                     "output directory: solution.csv, scores.csv, errors.csv, the recording")
        ->required();
    cli_->add_flag("--smooth", o_.smooth, "also score the fixed-interval smoother");
    addFaultManager(*cli_, o_);
  }
  bool usesBus() const override { return false; }
  int run(bus::Participant::Options& /*options*/, bus::ShutdownSignal& /*shutdown*/) override {
    o_.schedule = scheduleOf(schedule_);
    return evaluation::runRealCarBenchmark(o_);
  }

 private:
  evaluation::RealCarOptions o_;
  std::vector<double> schedule_;
};

void addGrid(CLI::App& app, const char* name, evaluation::Grid& grid, const char* text) {
  app.add_option_function<std::vector<double>>(
         name,
         [&grid](const std::vector<double>& v) {
           grid = {v[0], v[1], v[2]};
         },
         text)
      ->expected(3)
      ->delimiter(',');
}

class TimeOffsetCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    CLI::App* calibrate = app.add_subcommand(
        "calibrate", "settings of the filter configuration derived from a real log");
    calibrate->require_subcommand(1);
    cli_ = calibrate->add_subcommand(
        "time-offset",
        "the IMU's time offset against the GNSS solutions: the offset (added to "
        "inputs.imu.time_offset_s) that minimizes the filter's mean normalized innovation "
        "squared over the whole log, GNSS never withheld");
    cli_->add_option("dataset", o_.dataset, "data set YAML")->required()->check(CLI::ExistingFile);
    cli_->add_option("--filter", o_.filter, "navbus-filter YAML")
        ->required()
        ->check(CLI::ExistingFile);
    cli_->add_option("-o,--out", o_.out_dir, "output directory: time_offset.csv, the recording")
        ->required();
    addGrid(*cli_, "--imu-grid", o_.imu,
            "FROM,TO,STEP: offsets added to inputs.imu.time_offset_s [s] (-0.3,0.3,0.02)");
    addGrid(*cli_, "--velocity-grid", o_.velocity,
            "FROM,TO,STEP: inputs.gnss_fix.velocity_time_offset_s tried [s] (-0.3,0,0.02)");
    cli_->add_option("--rounds", o_.rounds, "the two searches alternated this often (2)")
        ->check(CLI::Range(1, 10));
  }
  bool usesBus() const override { return false; }
  int run(bus::Participant::Options& /*options*/, bus::ShutdownSignal& /*shutdown*/) override {
    return evaluation::runTimeOffsetCommand(o_);
  }

 private:
  evaluation::TimeOffsetOptions o_;
};

/// Under `navbus calibrate`, which TimeOffsetCommand creates (added before this one).
class MountingCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.get_subcommand("calibrate")
               ->add_subcommand("mounting",
                                "the IMU mounting's residual pitch and yaw against the vehicle's "
                                "direction of travel (what the non-holonomic constraint needs), "
                                "from the smoothed solution, GNSS never withheld, over the "
                                "epochs driven straight");
    cli_->add_option("dataset", o_.dataset, "data set YAML")->required()->check(CLI::ExistingFile);
    cli_->add_option("--filter", o_.filter, "navbus-filter YAML")
        ->required()
        ->check(CLI::ExistingFile);
    cli_->add_option("-o,--out", o_.out_dir, "output directory: the recording")->required();
    cli_->add_option("--min-speed", o_.straight.min_speed_mps,
                     "epochs below this speed are left out [m/s] (5)")
        ->check(CLI::Range(0.5, 100.0));
    cli_->add_option("--max-heading-rate", heading_rate_dps_,
                     "epochs turning faster are left out [deg/s] (2)")
        ->check(CLI::Range(0.01, 90.0));
  }
  bool usesBus() const override { return false; }
  int run(bus::Participant::Options& /*options*/, bus::ShutdownSignal& /*shutdown*/) override {
    o_.straight.max_heading_rate_radps = heading_rate_dps_ * units::kDeg;
    return evaluation::runMountingCommand(o_);
  }

 private:
  evaluation::MountingOptions o_;
  double heading_rate_dps_{2.0};
};

class AllanCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.add_subcommand(
        "allan",
        "noise densities of a recorded IMU from the Allan deviation of a stretch at rest (and, "
        "with --motion-from/--motion-to, in motion), as the filter configuration's ekf keys");
    cli_->add_option("recording", dir_, "recording directory (navbus import, navbus record)")
        ->required()
        ->check(CLI::ExistingDirectory);
    cli_->add_option("--from", from_s_,
                     "start of the stretch at rest [s after the first increment]")
        ->check(CLI::Range(0.0, 1e7));
    cli_->add_option("--to", to_s_, "its end [s after the first increment]")
        ->required()
        ->check(CLI::Range(0.0, 1e7));
    auto* motion_from =
        cli_->add_option("--motion-from", motion_from_s_,
                         "start of a stretch in motion: the vibration there against the stretch "
                         "at rest gives the densities in motion [s after the first increment]")
            ->check(CLI::Range(0.0, 1e7));
    auto* motion_to =
        cli_->add_option("--motion-to", motion_to_s_, "its end [s after the first increment]")
            ->check(CLI::Range(0.0, 1e7));
    motion_from->needs(motion_to);
    motion_to->needs(motion_from);
  }
  bool usesBus() const override { return false; }
  int run(bus::Participant::Options& /*options*/, bus::ShutdownSignal& /*shutdown*/) override {
    const evaluation::ImuNoiseSurvey rest = evaluation::surveyImuNoise(dir_, from_s_, to_s_);
    std::fputs(evaluation::formatSurvey(rest).c_str(), stdout);
    if (motion_to_s_ > 0.0) {
      const evaluation::ImuNoiseSurvey motion =
          evaluation::surveyImuNoise(dir_, motion_from_s_, motion_to_s_);
      std::fputs(
          evaluation::formatMotionNoise(motion, evaluation::motionNoise(rest, motion)).c_str(),
          stdout);
    }
    return 0;
  }

 private:
  std::string dir_;
  double from_s_{0.0};
  double to_s_{0.0};
  double motion_from_s_{0.0};
  double motion_to_s_{0.0};
};

}  // namespace

void addRealDataSubcommands(Subcommands& out) {
  out.push_back(std::make_unique<AllanCommand>());
  out.push_back(std::make_unique<ImportCommand>());
  out.push_back(std::make_unique<RealCarBenchmarkCommand>());
  out.push_back(std::make_unique<RealDataBenchmarkCommand>());
  out.push_back(std::make_unique<TimeOffsetCommand>());
  out.push_back(std::make_unique<MountingCommand>());
}

}  // namespace navbus::tool::cli
