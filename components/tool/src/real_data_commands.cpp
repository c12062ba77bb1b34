// Real logs, offline (no DDS participant): `navbus allan` reads a recorded IMU's noise densities
// from its standing start; `navbus import` turns a user's logs, described by a
// data set YAML, into a navbus recording (components/importers); `navbus benchmark real-car`
// scores the filter on one with GNSS outages (evaluation/real_car_benchmark.hpp).
#include <cstdio>

#include "navbus/evaluation/imu_noise_survey.hpp"
#include "navbus/evaluation/real_car_benchmark.hpp"
#include "navbus/importers/importer.hpp"
#include "subcommand.hpp"

namespace navbus::tool::cli {
namespace {

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
  }
  bool usesBus() const override { return false; }
  int run(bus::Participant::Options& /*options*/, bus::ShutdownSignal& /*shutdown*/) override {
    const auto description = importers::readDatasetDescription(dataset_);
    const auto report = importers::importDataset(description, out_dir_);
    std::fputs(report.text.c_str(), stdout);
    return 0;
  }

 private:
  std::string dataset_;
  std::string out_dir_;
};

class RealCarBenchmarkCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    CLI::App* benchmark = app.add_subcommand("benchmark", "benchmarks on real logs");
    benchmark->require_subcommand(1);
    cli_ = benchmark->add_subcommand(
        "real-car",
        "a car's log with GNSS outages: the filter runs causally without the GNSS solutions "
        "inside each outage; its antenna positions are scored against the withheld fixed epochs");
    cli_->add_option("dataset", o_.dataset, "data set YAML (config/datasets/drive_0708.yaml)")
        ->required()
        ->check(CLI::ExistingFile);
    cli_->add_option("--filter", o_.filter, "navbus-filter YAML (config/filter_drive_0708.yaml)")
        ->required()
        ->check(CLI::ExistingFile);
    cli_->add_option("--outages", o_.outages,
                     "outage list: `START END` per line, GPS seconds of week, # comments "
                     "(config/datasets/drive_0708_outages.txt)")
        ->required()
        ->check(CLI::ExistingFile);
    cli_->add_option("-o,--out", o_.out_dir,
                     "output directory: solution.csv (antenna, IMU rate), outages.csv, "
                     "scores.csv, the imported recording")
        ->required();
    cli_->add_flag("--smooth", o_.smooth,
                   "also score the fixed-interval (Rauch-Tung-Striebel) smoother over the same "
                   "forward run: smoothed.csv, smoothed_outages.csv");
  }
  bool usesBus() const override { return false; }
  int run(bus::Participant::Options& /*options*/, bus::ShutdownSignal& /*shutdown*/) override {
    return evaluation::runRealCarBenchmark(o_);
  }

 private:
  evaluation::RealCarOptions o_;
};

class AllanCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.add_subcommand(
        "allan",
        "noise densities of a recorded IMU from the Allan deviation of a stretch at rest, as the "
        "filter configuration's ekf keys");
    cli_->add_option("recording", dir_, "recording directory (navbus import, navbus record)")
        ->required()
        ->check(CLI::ExistingDirectory);
    cli_->add_option("--from", from_s_,
                     "start of the stretch at rest [s after the first increment]")
        ->check(CLI::Range(0.0, 1e7));
    cli_->add_option("--to", to_s_, "its end [s after the first increment]")
        ->required()
        ->check(CLI::Range(0.0, 1e7));
  }
  bool usesBus() const override { return false; }
  int run(bus::Participant::Options& /*options*/, bus::ShutdownSignal& /*shutdown*/) override {
    std::fputs(evaluation::formatSurvey(evaluation::surveyImuNoise(dir_, from_s_, to_s_)).c_str(),
               stdout);
    return 0;
  }

 private:
  std::string dir_;
  double from_s_{0.0};
  double to_s_{0.0};
};

}  // namespace

void addRealDataSubcommands(Subcommands& out) {
  out.push_back(std::make_unique<AllanCommand>());
  out.push_back(std::make_unique<ImportCommand>());
  out.push_back(std::make_unique<RealCarBenchmarkCommand>());
}

}  // namespace navbus::tool::cli
