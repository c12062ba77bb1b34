// A FaultOutput that keeps the decisions (numbered from 1) and the commands as they come, for the
// detectors' unit tests.
#pragma once

#include <cstdint>
#include <vector>

#include "navbus/fault_manager/fault_output.hpp"

namespace navbus::fault_manager::test {

class Recorder : public FaultOutput {
 public:
  std::uint32_t decide(navbus::FaultDecision& d) override {
    d.decision_id(static_cast<std::uint32_t>(decisions.size() + 1));
    decisions.push_back(d);
    return d.decision_id();
  }
  void command(navbus::FilterCommand& c) override { commands.push_back(c); }
  void satelliteKeptOut(int sv_id) override { kept_out.push_back(sv_id); }
  std::vector<navbus::FaultDecision> decisions;
  std::vector<navbus::FilterCommand> commands;
  std::vector<int> kept_out;
};

}  // namespace navbus::fault_manager::test
