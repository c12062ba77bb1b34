// A scenario: a truth trajectory seen by an IMU (error model, optional RLG dither in the raw
// stream), a GNSS receiver and a star tracker, with scheduled faults. Produces one SensorFrame
// per navigation interval; the same seed gives bit-identical data.
#pragma once

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
  bool dither{false};
  DitherSpec dither_spec;
  VibrationSpec vibration;
  ConstellationConfig constellation;
  GnssReceiverConfig gnss;
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
  Eigen::Vector3d frozen(SensorKind sensor, const Eigen::Vector3d& rate, double t);

  ScenarioConfig config_;
  std::unique_ptr<Trajectory> trajectory_;
  ImuErrorModel imu_;
  DitherModel dither_;
  VehicleVibration vibration_;
  Constellation constellation_;
  GnssReceiverModel receiver_;
  StarTrackerModel star_;
  Eigen::Vector3d star_bias_b_rad_{Eigen::Vector3d::Zero()};  ///< at the latest tracker sample
  std::mt19937_64 rng_;
  std::int64_t index_{0};
  Eigen::Vector3d last_accel_{Eigen::Vector3d::Zero()};  ///< last raw outputs (for stuck axes)
  Eigen::Vector3d last_gyro_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d stuck_accel_{Eigen::Vector3d::Constant(std::nan(""))};
  Eigen::Vector3d stuck_gyro_{Eigen::Vector3d::Constant(std::nan(""))};
};

}  // namespace navbus::sim
