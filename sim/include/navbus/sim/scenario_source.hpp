// A scenario: a truth trajectory seen by an IMU (error model, optional RLG dither in the raw
// stream) and by further IMU units of a redundant installation (each with its own mounting,
// lever arm, error model and noise), a GNSS receiver and a star tracker, with scheduled faults
// (IMU faults addressed to a unit) and by further GNSS receivers (pseudorange and clock faults
// addressed to a receiver). Produces one SensorFrame per navigation interval; the same
// seed gives bit-identical data.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "navbus/sim/constellation.hpp"
#include "navbus/sim/dither.hpp"
#include "navbus/sim/faults.hpp"
#include "navbus/sim/gnss_receiver.hpp"
#include "navbus/sim/imu_model.hpp"
#include "navbus/sim/samples.hpp"
#include "navbus/sim/star_tracker_model.hpp"
#include "navbus/sim/trajectory.hpp"
#include "navbus/sim/vibration.hpp"

namespace navbus::sim {

/// A further IMU of a redundant installation. It senses the body's motion at its own place and in
/// its own axes: rates C_u_b w and specific force C_u_b (f + dw/dt x r + w x (w x r)) (a rigid
/// body; r the lever arm), then its own errors; no dither.
struct ImuUnit {
  /// Rotates body-axis vectors into the unit's axes (the unit's mounting).
  Eigen::Matrix3d c_u_b{Eigen::Matrix3d::Identity()};
  Eigen::Vector3d lever_arm_b_m{Eigen::Vector3d::Zero()};  ///< from the scenario's IMU [m, body]
  ImuSpec imu;
};

/// A further GNSS receiver of a redundant installation: its antenna's place, its own clock and
/// noise (the scenario's receiver model otherwise), the same satellites in view; the same epochs.
struct GnssUnit {
  Eigen::Vector3d antenna_b_m{Eigen::Vector3d::Zero()};  ///< from the body origin [m, body]
  double clock_bias_m{0.0};                              ///< c * clock bias at the start
  double clock_drift_mps{0.0};                           ///< c * clock drift at the start
};

struct ScenarioConfig {
  std::string name{"default"};
  bool orbit{false};  ///< true: circular orbit (seed 001), else vehicle segments
  VehicleStart vehicle;
  std::vector<Segment> segments;
  OrbitStart orbit_start;
  core::earth::GravityModel gravity{core::earth::GravityModel::kWgs84Normal};
  std::int64_t start_time_ns{0};
  std::int64_t imu_period_ns{10'000'000};
  int raw_samples_per_increment{24};
  int gnss_every_n_increments{100};         ///< 0: no GNSS
  int star_tracker_every_n_increments{20};  ///< 0: no star tracker
  ImuSpec imu;
  std::vector<ImuUnit> extra_imus;  ///< units 1, 2, ... beside the scenario's IMU (unit 0)
  bool dither{false};
  DitherSpec dither_spec;
  VibrationSpec vibration;
  ConstellationConfig constellation;
  GnssReceiverConfig gnss;
  std::vector<GnssUnit>
      extra_receivers;  ///< receivers 1, 2, ... beside the scenario's (receiver 0)
  StarTrackerSpec star_tracker;
  FaultSchedule faults;
  std::uint64_t seed{1};
};

class ScenarioSource {
 public:
  explicit ScenarioSource(const ScenarioConfig& config);
  SensorFrame next();
  /// The same frame written into `frame`, whose raw-sample buffer it reuses: no allocation per
  /// IMU frame once it has grown (the offline runner recycles its frames).
  void next(SensorFrame& frame);
  std::int64_t index() const { return index_; }
  /// The truth at the current time (before the first next(): the initial state).
  core::NavState truth() const { return trajectory_->state(); }
  const ScenarioConfig& config() const { return config_; }

 private:
  /// What an IMU unit's outputs remember from one raw sample to the next (stuck axes).
  struct UnitOutputs {
    Eigen::Vector3d last_accel{Eigen::Vector3d::Zero()};  ///< last raw outputs
    Eigen::Vector3d last_gyro{Eigen::Vector3d::Zero()};
    Eigen::Vector3d stuck_accel{Eigen::Vector3d::Constant(std::nan(""))};
    Eigen::Vector3d stuck_gyro{Eigen::Vector3d::Constant(std::nan(""))};
  };
  struct ExtraUnit {
    ImuErrorModel model;
    UnitOutputs outputs;
    /// The body rate of the previous raw sample, for dw/dt (NaN before the first)
    Eigen::Vector3d previous_rate_b{Eigen::Vector3d::Constant(std::nan(""))};
  };
  Eigen::Vector3d frozen(UnitOutputs& unit, int unit_index, SensorKind sensor,
                         const Eigen::Vector3d& rate, double t);
  /// The scale-factor and noise faults of unit `unit` (spec `spec`) on one raw sample: `input`
  /// the true increments in the unit's axes, `sensed` its output so far.
  void applyAxisFaults(const PerfectIncrement& input, const ImuSpec& spec, int unit, double t,
                       double dt, PerfectIncrement& sensed);
  /// One raw sample of extra unit k, added to its increment in `f`.
  void senseExtraUnit(int k, const PerfectIncrement& perfect, const Eigen::Vector3d& f_b,
                      const Eigen::Vector3d& vibration_f_b, const Eigen::Vector3d& vibration_w_b,
                      double t, double dt, SensorFrame& f);

  ScenarioConfig config_;
  std::unique_ptr<Trajectory> trajectory_;
  ImuErrorModel imu_;
  DitherModel dither_;
  VehicleVibration vibration_;
  Constellation constellation_;
  GnssReceiverModel receiver_;
  struct ExtraReceiver {
    GnssReceiverModel model;
    std::mt19937_64 rng;
  };
  std::vector<ExtraReceiver> extra_receivers_;
  /// The further receivers' epochs at the scenario receiver's epoch time (f.extra_gnss).
  void observeExtraReceivers(std::int64_t t_ns, const Eigen::Vector3d& r_e,
                             const Eigen::Matrix3d& C_n_e, double t_s, SensorFrame& f);
  StarTrackerModel star_;
  Eigen::Vector3d star_bias_b_rad_{Eigen::Vector3d::Zero()};  ///< at the latest tracker sample
  std::mt19937_64 rng_;
  /// The added noise of noise-increase faults (drawn only while one is active, so that every
  /// other stream is the same with or without the fault).
  std::mt19937_64 fault_rng_;
  std::int64_t index_{0};
  UnitOutputs outputs_;  ///< the scenario's IMU (unit 0)
  std::vector<ExtraUnit> extra_;
};

}  // namespace navbus::sim
