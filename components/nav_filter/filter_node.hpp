// navbus-filter's participant: DataReaders feed the filter pipeline (filter_pipeline.hpp),
// whose solutions and diagnostics go to DataWriters; timers bound the wait for silent streams
// and republish the held solution while inertial data is lost.
#pragma once

#include <string>

#include <navbus_idl/NavigationPubSubTypes.h>

#include "filter_config.hpp"
#include "filter_pipeline.hpp"
#include "navbus/bus/participant.hpp"

namespace navbus::nav_filter {

class FilterNode {
 public:
  FilterNode(bus::Participant& participant, const FilterConfig& config);

  /// Releases ready inputs (after every reader dispatch and periodically).
  void pump();
  std::string summary() const { return pipeline_.summary(); }

 private:
  void updateState();

  bus::Participant& participant_;
  bus::Writer<navbus::NavigationSolution> solution_writer_;
  bus::Writer<navbus::FilterDiagnostics> diagnostics_writer_;
  FilterPipeline pipeline_;
};

}  // namespace navbus::nav_filter
