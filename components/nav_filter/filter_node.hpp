// navbus-filter's participant logic: validate inputs, order them deterministically, run the
// strapdown mechanization (components/core), publish the solution, apply decisions and commands.
#pragma once

#include <cstdint>
#include <set>
#include <string>
#include <variant>

#include <navbus_idl/FaultPubSubTypes.h>
#include <navbus_idl/GnssPubSubTypes.h>
#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>
#include <navbus_idl/StarTrackerPubSubTypes.h>

#include "filter_config.hpp"
#include "input_sequencer.hpp"
#include "navbus/bus/participant.hpp"
#include "navbus/bus/validation.hpp"
#include "navbus/core/tightly_coupled_ekf.hpp"

namespace navbus::nav_filter {

/// Stream ranks: at equal times the increment is integrated before measurements are used.
enum StreamRank : int { kRankImu = 0, kRankGnssObs = 1, kRankGnssFix = 2, kRankStarTracker = 3 };

/// A measurement epoch that passed validation. Mechanization-only mode does not use its
/// content; it is sequenced so that the processing order is fixed before fusion arrives.
struct MeasurementEpoch {
  StreamRank kind;
};

/// A validated GNSS observation epoch: satellite clock corrections applied, ready for the
/// tightly coupled update.
struct GnssEpochInput {
  std::vector<core::SatelliteObservation> satellites;
};

using FilterInput = std::variant<core::ImuIncrement, MeasurementEpoch, GnssEpochInput>;

class FilterNode {
 public:
  FilterNode(bus::Participant& participant, const FilterConfig& config);

  /// Releases ready inputs (call after every reader dispatch and periodically).
  void pump();
  std::string summary() const;

 private:
  void onImu(const navbus::ImuIncrement& msg);
  template <class Sample>
  void onMeasurement(bus::StreamGate& gate, const Sample& msg, std::uint32_t id,
                     const std::optional<InputConfig>& expected, StreamRank rank);
  void onGnssObservations(const navbus::GnssObservationEpoch& msg);
  void fuseGnss(const GnssEpochInput& epoch);
  void publishDiagnostics();
  void onDecision(const navbus::FaultDecision& d);
  void onCommand(const navbus::FilterCommand& c);
  void queue(bus::StreamGate& gate, StreamId id, std::int64_t time_ns, FilterInput input);
  void process(StreamId id, std::int64_t time_ns, const FilterInput& input);
  void integrate(const core::ImuIncrement& inc);
  void publishSolution();
  void reset();
  void updateState();

  bus::Participant& participant_;
  FilterConfig config_;
  InputSequencer<FilterInput> sequencer_;
  core::TightlyCoupledEkf ekf_;  ///< inertial-only mode: propagation without updates
  bus::Writer<navbus::NavigationSolution> solution_writer_;
  bus::Writer<navbus::FilterDiagnostics> diagnostics_writer_;
  std::uint64_t diagnostics_seq_{0};
  std::uint64_t gnss_epochs_fused_{0};
  bus::StreamGate imu_gate_;
  bus::StreamGate gnss_obs_gate_;
  bus::StreamGate gnss_fix_gate_;
  bus::StreamGate star_gate_;

  navbus::FilterMode mode_{navbus::MODE_INITIALIZING};
  std::uint32_t fault_flags_{0};
  std::int64_t next_output_ns_{0};
  std::uint64_t solution_seq_{0};
  std::uint64_t imu_used_{0};
  std::uint64_t imu_gaps_{0};
  std::uint64_t decisions_applied_{0};
  std::uint64_t commands_applied_{0};
  std::uint64_t commands_refused_{0};
  std::set<std::uint16_t> excluded_satellites_;
  Eigen::Vector3d accel_bias_b_mps2_{Eigen::Vector3d::Zero()};  ///< compensated by command
  Eigen::Vector3d gyro_bias_b_radps_{Eigen::Vector3d::Zero()};
};

}  // namespace navbus::nav_filter
