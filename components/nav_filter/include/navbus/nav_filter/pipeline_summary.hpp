// What the filter pipeline counts beside the engine and the command gate, and the one-line
// summary the participant and `navbus offline` print at the end.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "navbus/core/engine/navigation_engine.hpp"
#include "navbus/core/ins/output_predictor.hpp"
#include "navbus/nav_filter/command_gate.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/nav_filter/solution_flags.hpp"

namespace navbus::nav_filter {

struct PipelineCounters {
  std::uint64_t decisions_seen{0};
  std::uint64_t unused_samples{0};  ///< samples of streams the configuration does not use
  std::uint64_t new_runs{0};
  std::uint64_t solutions_earlier_runs{0};   ///< published before the latest new run
  std::uint64_t increments_earlier_runs{0};  ///< integrated before the latest new run
  std::uint64_t onset_recoveries{0};         ///< restores to before a fault's onset
  std::uint64_t onset_beyond_history{0};     ///< ... the history could not reach
  std::uint64_t late_merged{0};              ///< samples after their place, merged by rewinding
  std::uint64_t rewinds{0};
  /// Solutions published with covariance_valid false (inconsistent or re-initialising): kept
  /// here, not in the engine, because a rollback re-processes the engine's own counters.
  std::uint64_t solutions_untrusted{0};
  std::uint64_t stalls{0};  ///< pauses of the participant's own process
  std::int64_t longest_stall_ns{0};
};

/// Everything the summary line reads.
struct PipelineView {
  const FilterConfig& config;
  const core::NavigationEngine& engine;
  const CommandCounters& commands;
  const SolutionFlags& flags;
  const core::OutputPredictorCounters& low_latency;
  const PipelineCounters& counters;
  std::uint64_t solutions_published;
  std::uint64_t sequencer_timeouts;
  std::size_t pending;
  std::uint64_t merge_grown;         ///< the merge's buffer grew beyond its reserve
  std::uint64_t progress_reports;    ///< the fault manager's progress reports
  std::uint64_t progress_held;       ///< ... that came before the command they name
  std::uint64_t judgement_timeouts;  ///< owed judgements that did not come within the budget
};

std::string describePipeline(const PipelineView& v);

}  // namespace navbus::nav_filter
