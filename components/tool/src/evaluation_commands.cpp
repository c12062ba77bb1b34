// `navbus offline`, `montecarlo` and `rinex`: navbus's own figures, run by the evaluation
// library without a DDS participant.
#include <map>
#include <string>

#include "navbus/bus/config.hpp"
#include "navbus/evaluation/evaluation.hpp"
#include "navbus/evaluation/real_data.hpp"
#include "navbus/evaluation/recording_runner.hpp"
#include "subcommand.hpp"

namespace navbus::tool::cli {
namespace {

/// `--start` of offline and montecarlo: align from the inputs (true) or as the filter file says.
const std::map<std::string, bool> kStartChoices{{"align", true}, {"config", false}};

class OfflineCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.add_subcommand(
        "offline",
        "run a scenario (solution, truth, error CSV) or a recording (solution CSV) through the "
        "filter without DDS");
    auto* scenario =
        cli_->add_option("--scenario", offline.scenario, "scenario YAML (sim/scenarios)")
            ->check(CLI::ExistingFile);
    auto* recording =
        cli_->add_option("--recording", recording_.recording,
                         "a recording instead of a scenario: a directory of CSV files (navbus "
                         "import, navbus record) or an MCAP file (navbus record --format mcap; one "
                         "cut short is read up to its last complete record): its sensor topics in "
                         "data-time order, as navbus replay sends them; --start, --seed and "
                         "--duration do not apply")
            ->check(CLI::ExistingPath);
    scenario->excludes(recording);
    cli_->add_flag("--innovations", recording_.innovations,
                   "with --recording: also write innovations.csv, every fused GNSS fix's "
                   "position and velocity innovations with their sigmas, along and across the "
                   "track (the fix's error model is read from them: docs/real_data.md)")
        ->needs(recording);
    cli_->add_flag("--smooth", recording_.smooth,
                   "with --recording: a fixed-interval (Rauch-Tung-Striebel) smoother runs "
                   "backward over the forward filter's states and covariances; writes "
                   "smoothed.csv (the IMU's position, velocity, attitude and smoothed sigmas)")
        ->needs(recording);
    cli_->add_option("--filter", offline.filter, "navbus-filter YAML (config/)")
        ->required()
        ->check(CLI::ExistingFile);
    cli_->add_option("--seed", offline.seed, "random seed (0: the scenario's)");
    cli_->add_option("--duration", offline.duration_s,
                     "seconds of data (0: the scenario's timing.duration_s)")
        ->check(CLI::Range(0.0, 1e6));
    cli_->add_option("-o,--out", offline.out_dir, "output directory (created)")->required();
    cli_->add_option(
            "--start", offline.align,
            "align: the filter aligns from its inputs, as on a bus where nobody knows the "
            "truth (default); config: it starts as the filter YAML says (its initial_state "
            "if it has one), as navbus-filter with that file would")
        ->transform(CLI::CheckedTransformer(kStartChoices))
        ->default_str("align");
    cli_->add_option("--fault-manager", offline.fault_manager,
                     "navbus-fault-manager YAML: run the fault pipeline (GLR) in the same process, "
                     "its commands to the filter; writes decisions.csv and commands.csv")
        ->check(CLI::ExistingFile);
  }
  bool usesBus() const override { return false; }
  int run(bus::Participant::Options& /*options*/, bus::ShutdownSignal& /*shutdown*/) override {
    if (!recording_.recording.empty()) {
      recording_.filter = offline.filter;
      recording_.fault_manager = offline.fault_manager;
      recording_.out_dir = offline.out_dir;
      return evaluation::runRecordingCommand(recording_);
    }
    if (offline.scenario.empty())
      throw bus::ConfigError("navbus offline needs --scenario or --recording");
    return evaluation::runOfflineCommand(offline);
  }

 private:
  evaluation::OfflineOptions offline;
  evaluation::RecordingOptions recording_;
};

class MonteCarloCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.add_subcommand(
        "montecarlo", "Monte Carlo over seeds: RMS and max errors, average NEES with its 95% band");
    cli_->add_option("--scenario", mc.scenario, "scenario YAML")
        ->required()
        ->check(CLI::ExistingFile);
    cli_->add_option("--filter", mc.filters, "navbus-filter YAML, repeatable (one row each)")
        ->required()
        ->check(CLI::ExistingFile);
    cli_->add_option("--fusion", mc.fusions,
                     "override `fusion` of every filter: centralized federated adaptive")
        ->delimiter(',');
    cli_->add_option("--policy", mc.policies,
                     "override multi_dimensional.policy: mdf continue reset_all")
        ->delimiter(',');
    cli_->add_option("--runs", mc.runs, "runs per configuration")->check(CLI::Range(1, 100000));
    cli_->add_option("--fault-manager", mc.fault_manager,
                     "navbus-fault-manager YAML: run the fault pipeline and report detection time, "
                     "isolation, magnitude error and false alarms per configuration")
        ->check(CLI::ExistingFile);
    cli_->add_option("--csv", mc.csv_dir,
                     "directory for nees.csv (average NEES per epoch, 95 % band) and, with "
                     "--fault-manager, faults.csv (one row per run)");
    cli_->add_option("--threads", mc.threads, "parallel runs (0: one per core)")
        ->check(CLI::Range(0, 256));
    cli_->add_option("--first-seed", mc.first_seed, "seed of the first run (then +1 per run)")
        ->check(CLI::Range(1ull, 1ull << 60));
    cli_->add_option("--duration", mc.duration_s, "seconds of data (0: the scenario's)")
        ->check(CLI::Range(0.0, 1e6));
    cli_->add_option("--from", mc.from_s, "statistics from this many seconds after the start")
        ->check(CLI::Range(0.0, 1e6));
    cli_->add_flag("--no-perturb", mc_no_perturb,
                   "start every run at the true initial state instead of a draw from the "
                   "filter's initial sigmas");
    cli_->add_option("--start", mc.align,
                     "align: every filter aligns from its inputs (default; prints the alignment's "
                     "time, attitude source and start error against its sigmas); config: a filter "
                     "with an initial_state starts from a draw around the truth with its initial "
                     "sigmas (--no-perturb: the truth), one without aligns")
        ->transform(CLI::CheckedTransformer(kStartChoices))
        ->default_str("align");
    cli_->add_option("--recovery-after", mc.recovery_after_s,
                     "instants [s after start] after which to measure the convergence time")
        ->delimiter(',');
    cli_->add_option("--recovery-threshold", mc.recovery_threshold_m,
                     "horizontal position error [m] that counts as converged")
        ->check(CLI::Range(1e-6, 1e6));
    cli_->add_option("--recovery-window", mc.recovery_window_s,
                     "the error must stay below the threshold this long [s]")
        ->check(CLI::Range(0.0, 1e6));
  }
  bool usesBus() const override { return false; }
  int run(bus::Participant::Options& /*options*/, bus::ShutdownSignal& /*shutdown*/) override {
    mc.perturb_initial = !mc_no_perturb;
    return evaluation::runMonteCarloCommand(mc);
  }

 private:
  evaluation::MonteCarloOptions mc;
  bool mc_no_perturb{false};
};

class RinexCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.add_subcommand("rinex",
                              "real GPS data: RINEX 2 observation + navigation files -> single "
                              "point fixes and the static "
                              "receiver filter, optionally monitored by the fault manager's GLR");
    cli_->add_option("--obs", real.obs, "RINEX 2 observation file (.yyo)")
        ->required()
        ->check(CLI::ExistingFile);
    cli_->add_option("--nav", real.nav, "RINEX 2 GPS navigation file (.yyn)")
        ->required()
        ->check(CLI::ExistingFile);
    cli_->add_option("-o,--out", real.out_dir, "output directory (created)")->required();
    cli_->add_option("--fault-manager", real.fault_manager,
                     "navbus-fault-manager YAML (e.g. config/fault_manager_static.yaml): run the "
                     "GLR on the filter; writes decisions.csv and commands.csv")
        ->check(CLI::ExistingFile);
    cli_->add_option("--reference", real.reference,
                     "reference position x,y,z ECEF [m] (default: the header's APPROX POSITION)")
        ->delimiter(',');
    cli_->add_option("--inject-ramp", real.ramp,
                     "sv,rate_mps,onset_s: add rate * (t - onset) to one satellite's pseudoranges "
                     "from onset_s after the first epoch")
        ->delimiter(',');
  }
  bool usesBus() const override { return false; }
  int run(bus::Participant::Options& /*options*/, bus::ShutdownSignal& /*shutdown*/) override {
    return evaluation::runRealDataCommand(real);
  }

 private:
  evaluation::RealDataOptions real;
};

}  // namespace

void addEvaluationSubcommands(Subcommands& out) {
  out.push_back(std::make_unique<OfflineCommand>());
  out.push_back(std::make_unique<MonteCarloCommand>());
  out.push_back(std::make_unique<RinexCommand>());
}

}  // namespace navbus::tool::cli
