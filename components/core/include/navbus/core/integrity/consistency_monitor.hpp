// The filter watches itself: a test of whether its own covariance explains its innovations.
// Each aiding epoch gives the normalized innovation squared of the rows offered to the update
// (gated rows included: a filter that has lost its way gates everything, and that must count),
//   NIS_k = sum_i nu_i^2 / V_i,   dof_k = number of rows,
// with nu_i and V_i = H P- H^T + R of each sequentially processed row (for a linear model the
// sum equals the batch nu^T V^-1 nu). Over a sliding window of the last N epochs, a consistent
// filter has sum NIS ~ chi-square(sum dof); the window is inconsistent when
//   P(chi-square(sum dof) >= sum NIS) < alpha,
// so on a consistent filter a fraction alpha of the tested epochs alarms (the windows overlap:
// alarms come in runs, the rate per epoch is what alpha sets). An alarm that has lasted
// `reinitialise_after_s` asks for re-initialisation; the window is cleared after it. Pure math.
#pragma once

#include <array>
#include <cstdint>

namespace navbus::core {

struct ConsistencyConfig {
  bool enabled{true};
  int window_epochs{10};                 ///< N: epochs summed per test (1..kMaxWindow)
  double false_alarm_probability{1e-4};  ///< alpha per tested epoch on a consistent filter
  double reinitialise_after_s{10.0};     ///< an alarm this long asks for re-initialisation [s]
  /// At each alarm the filter raises its accelerometer and gyro bias sigmas to at least their
  /// turn-on sigmas (ekf.accel_bias_sigma_ug, gyro_bias_sigma_deg_per_h): the model stopped
  /// fitting, and a sensor whose bias shifted is what an inertial filter can learn again. Not
  /// the ConsistencyMonitor's concern (it only judges); the engine acts on it.
  bool inflate_imu_biases_on_alarm{false};
};

struct ConsistencyCounters {
  std::uint64_t epochs_tested{0};        ///< epochs with a full window
  std::uint64_t epochs_inconsistent{0};  ///< ... whose window failed the test
  std::uint64_t alarms{0};               ///< consistent -> inconsistent transitions
  std::uint64_t reinitialisations{0};    ///< alarms that lasted reinitialise_after_s
  double nis_sum{0.0};                   ///< every epoch's NIS, summed ...
  std::uint64_t rows{0};                 ///< ... over this many rows (mean NIS per row: ~1)
};

/// The normalized innovations squared of one kind of aiding row, summed over a run: a mean of
/// about 1 says the covariance and the measurement noise explain that stream's innovations.
struct InnovationStatistics {
  double nis_sum{0.0};
  std::uint64_t rows{0};
  /// One row with innovation nu and its variance V = H P H^T + R (V <= 0: not offered).
  void add(double innovation, double innovation_var) {
    if (!(innovation_var > 0.0)) return;
    nis_sum += innovation * innovation / innovation_var;
    ++rows;
  }
  double mean() const { return rows > 0 ? nis_sum / static_cast<double>(rows) : 0.0; }
};

class ConsistencyMonitor {
 public:
  static constexpr int kMaxWindow = 64;

  void configure(const ConsistencyConfig& config);
  /// One epoch's normalized innovation squared over `dof` rows (dof 0: nothing offered).
  void onEpoch(std::int64_t time_ns, double nis, int dof);
  /// The latest full window failed the test.
  bool inconsistent() const { return inconsistent_; }
  /// The alarm has lasted reinitialise_after_s: re-initialise (then call restart()).
  bool reinitialisationDue() const { return reinitialise_due_; }
  /// Starts over (after a re-initialisation, or a new run): empty window, no alarm.
  void restart();
  /// Tail probability of the latest full window (1 before the window is full).
  double lastProbability() const { return last_probability_; }
  /// The latest full window's NIS per row (about 1 when consistent; 0 before the window is
  /// full): a filter lane's test ratio.
  double windowNisPerRow() const { return window_nis_per_row_; }
  const ConsistencyCounters& counters() const { return counters_; }
  const ConsistencyConfig& config() const { return config_; }

 private:
  struct Epoch {
    double nis{0.0};
    int dof{0};
  };
  ConsistencyConfig config_;
  std::array<Epoch, kMaxWindow> window_{};
  int count_{0}, next_{0};
  bool inconsistent_{false};
  bool reinitialise_due_{false};
  std::int64_t alarm_since_ns_{0};
  double last_probability_{1.0};
  double window_nis_per_row_{0.0};
  ConsistencyCounters counters_;
};

}  // namespace navbus::core
