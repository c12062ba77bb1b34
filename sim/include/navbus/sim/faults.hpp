// Fault injection scheduled by the scenario (seeds 000, 001, 003, 004). Times are seconds since
// the scenario start; sizes are SI. Each query answers what is active at a time.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace navbus::sim {

enum class FaultKind {
  kImuBiasStep,        ///< seed 000 table 2: a step on one accelerometer or gyro axis
  kImuBiasRamp,        ///< a bias growing at `slope` from start, saturating at `saturation`
  kPseudorangeRamp,    ///< seed 000 table 3: slope [m/s] from start, saturating at `saturation`
  kGnssPositionPulse,  ///< seed 001: a position error [m, NED] on the fixes while active
  kSensorStuck,        ///< seed 003: an axis output frozen at its value at the start
  kGnssOutage,         ///< seed 004: no GNSS epochs or fixes while active (of one receiver, or all)
  kStarTrackerOutage,  ///< no star-tracker solution while active
  kStarTrackerBias,    ///< a star-tracker attitude bias [rad, body] while active
  kPseudorangeStep,  ///< one satellite's pseudoranges of one receiver offset by `magnitude` [m] (a
                     ///< spoofed satellite)
  kReceiverClockJump,   ///< a receiver's clock steps: every pseudorange of it + `magnitude` [m] =
                        ///< c * the jump
  kImuScaleFactorStep,  ///< one axis of a unit reads (1 + `magnitude`) times its input from start
  kImuNoiseIncrease,    ///< one axis of a unit: its white noise density times `magnitude` (>= 1)
  kGnssMultipath        ///< one satellite of one receiver: + `magnitude` sin(2 pi (t - start) /
                        ///< `period_s`) [m]
};

enum class SensorKind { kAccelerometer, kGyro };

struct Fault {
  FaultKind kind{FaultKind::kImuBiasStep};
  double start_s{0.0};
  double end_s{1e300};  ///< active while start <= t < end
  SensorKind sensor{SensorKind::kAccelerometer};
  int axis{0};  ///< 0..2
  /// IMU faults: the unit (0: the scenario's IMU; k: ScenarioConfig::extra_imus[k - 1]).
  int unit{0};
  std::uint32_t sensor_id{0};  ///< IMU faults: the unit's sensor id (ImuIncrement.sensor_id)
  /// Pseudorange and clock faults, and an outage of one receiver: the receiver (0: the
  /// scenario's; k: ScenarioConfig::extra_receivers[k - 1]); an outage of every receiver: -1.
  int receiver{0};
  std::uint32_t receiver_id{0};  ///< ... its receiver id (GnssObservationEpoch.receiver_id)
  int sv_id{0};
  double magnitude{0.0};  ///< bias step [m/s^2 | rad/s]; pseudorange step or clock jump [m]
  /// Ramps: pseudorange [m/s], IMU bias [m/s^2 | rad/s per s]
  double slope{0.0};
  /// Ramps: the size they stop growing at, 0: none [m | m/s^2 | rad/s]
  double saturation{0.0};
  Eigen::Vector3d vector{Eigen::Vector3d::Zero()};  ///< position pulse [m, NED] or ST bias [rad]
  double period_s{0.0};  ///< multipath: the period of the reflected path's phase [s]
};

class FaultSchedule {
 public:
  FaultSchedule() = default;
  explicit FaultSchedule(std::vector<Fault> faults) : faults_(std::move(faults)) {}

  /// Additional accelerometer and gyro biases [m/s^2, rad/s, the unit's axes] of an IMU unit at
  /// t (steps and ramps).
  Eigen::Vector3d accelBias(double t, int unit = 0) const {
    return imuBias(t, SensorKind::kAccelerometer, unit);
  }
  Eigen::Vector3d gyroBias(double t, int unit = 0) const {
    return imuBias(t, SensorKind::kGyro, unit);
  }
  /// Scale-factor errors [1, the unit's axes] of a unit at t: an axis reads (1 + s) times its
  /// input.
  Eigen::Vector3d scaleError(double t, SensorKind sensor, int unit = 0) const;
  /// Factor on each axis's white-noise density of a unit at t (1: as specified).
  Eigen::Vector3d noiseFactor(double t, SensorKind sensor, int unit = 0) const;
  /// Axes frozen at t: the start time of the stuck fault per axis, or nothing.
  std::optional<double> stuckSince(SensorKind sensor, int axis, double t, int unit = 0) const;
  /// Error added to a satellite's pseudorange of a receiver at t [m]: ramps, steps and the
  /// receiver's clock jumps.
  double pseudorangeError(int sv_id, double t, int receiver = 0) const;
  Eigen::Vector3d positionPulse(double t) const;
  /// Every receiver is out at t.
  bool gnssOut(double t) const;
  /// Receiver `receiver` (0: the scenario's) is out at t: its own outage or every receiver's.
  bool receiverOut(double t, int receiver) const;
  bool starTrackerOut(double t) const { return any(FaultKind::kStarTrackerOutage, t); }
  Eigen::Vector3d starTrackerBias(double t) const;
  const std::vector<Fault>& faults() const { return faults_; }

 private:
  Eigen::Vector3d imuBias(double t, SensorKind sensor, int unit) const;
  bool any(FaultKind kind, double t) const;
  static bool active(const Fault& f, double t) { return t >= f.start_s && t < f.end_s; }
  std::vector<Fault> faults_;
};

const char* faultKindName(FaultKind kind);

}  // namespace navbus::sim
