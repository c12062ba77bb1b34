// `navbus replay RECORDING`: a recording made by `navbus record` back onto the bus, so that a
// recorded run can be re-run through a new filter. RECORDING is a directory of CSV files or an
// MCAP file. Every sensor topic recorded in it is published with its recorded content (sequence
// numbers and data time stamps unchanged, bit for bit: record writes shortest round-trip numbers
// to CSV, and the samples' CDR bytes to MCAP), paced by the samples' data times (or, with --pace
// source, by the DDS source time stamps record wrote beside them: an MCAP message's publish
// time) scaled by --speed
// (0: as fast as the reliable writers take them). At the end each stream is disposed, as the
// simulator does, so a filter knows the data ended rather than was lost.
#pragma once

#include <string>
#include <vector>

#include "navbus/bus/participant.hpp"

namespace navbus::tool {

struct ReplayOptions {
  /// The recording: a directory with <topic with / as _>.csv per topic, or an MCAP file.
  std::string recording;
  double speed{1.0};  ///< 1: real time; 2: twice as fast; 0: no pacing
  /// "data": paced by the samples' data times (a fast-paced recording plays at the speed of its
  /// data); "source": by the recorded DDS source time stamps (the bus timing as recorded,
  /// jitter included; needs record's source_timestamp_ns column).
  std::string pace{"data"};
  double match_timeout_s{10.0};     ///< wait this long for a reader of every replayed topic
  std::vector<std::string> topics;  ///< empty: every sensor topic with a file in dir
  /// "TOPIC=N": wait for N readers of TOPIC before the first sample (default 1 per topic), so
  /// that no participant joins after the data began (the writers are volatile, as the
  /// simulator's, whose timing.min_readers this mirrors).
  std::vector<std::string> min_readers;
};

/// The topics replay publishes (the sensor inputs of a filter).
const std::vector<std::string>& replayableTopics();

/// Returns an exit code: 0, runtime error when a topic found no reader in time, configuration
/// error (thrown as bus::ConfigError) for a missing or malformed file, naming file, line,
/// column and value.
int runReplayCommand(const bus::Participant::Options& participant, const ReplayOptions& options,
                     bus::ShutdownSignal& shutdown);

}  // namespace navbus::tool
