// The cost of filter lanes: the triplex aircraft's samples (three navigation-grade IMUs at
// 100 Hz, pseudoranges and fixes at 1 Hz; sim/scenarios/seed000_triplex.yaml) through the
// filter participant's DDS-free path (LaneSet, as navbus-filter runs it) with one lane (unit 1's
// samples alone, config/filter_seed000_tc.yaml) and with three (config/filter_triplex.yaml),
// each without a fault monitor. Prints the time per IMU cycle (one increment of every unit) of
// each, the median of `passes` alternating passes after a warm-up, and the cost of each extra lane
// as a ratio to the single filter's (target <= 1: a lane costs no more than a filter).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <variant>
#include <vector>

#include "filter_samples.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/bus/health.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/nav_filter/lane_set.hpp"

namespace {

using namespace navbus;

nav_filter::FilterConfig filterConfig(const std::string& path) {
  YAML::Node yaml = bus::loadYamlFile(path);
  yaml.remove("fault_monitor");  // no fault manager in this process: nothing to wait for
  return nav_filter::parseFilterConfig(yaml);
}

/// One pass over the samples: seconds spent after `warmup` cycles. `unit_one_only`: the other
/// units' increments are not fed (a one-IMU filter beside the triplex would refuse them).
double pass(const nav_filter::FilterConfig& cfg,
            const std::vector<std::vector<bench::FilterSample>>& samples, std::size_t warmup,
            bool unit_one_only, std::uint64_t& solutions) {
  bus::HealthCounters health("lanes-benchmark");
  nav_filter::LaneSet lanes(cfg, health,
                            {{[&](const NavigationSolution&) { ++solutions; }, nullptr}, nullptr});
  std::chrono::steady_clock::duration timed{};
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    std::int64_t now = 0;
    for (const bench::FilterSample& s : samples[k]) {
      const auto* inc = std::get_if<ImuIncrement>(&s);
      if (unit_one_only && inc != nullptr && inc->sensor_id() != cfg.imu.id) continue;
      now = std::max(now, bench::feed(lanes, s));
    }
    lanes.pump(now);
    const auto t1 = std::chrono::steady_clock::now();
    if (k >= warmup) timed += t1 - t0;
  }
  return std::chrono::duration<double>(timed).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const std::string root = argc > 1 ? argv[1] : ".";
  const int cycles = argc > 2 ? std::atoi(argv[2]) : 20000;
  const int passes = argc > 3 ? std::max(1, std::atoi(argv[3])) : 3;
  const auto sim =
      sensor_sim::parseSimConfig(bus::loadYamlFile(root + "/sim/scenarios/seed000_triplex.yaml"));
  const nav_filter::FilterConfig one = filterConfig(root + "/config/filter_seed000_tc.yaml");
  const nav_filter::FilterConfig three = filterConfig(root + "/config/filter_triplex.yaml");
  const auto samples = bench::filterSamples(sim, cycles);
  // Warm-up: longer than the recovery history, so that its queues are at their steady size.
  const auto warmup = static_cast<std::size_t>(
      std::min<double>(cycles / 2, 1.5 * 1e-9 * static_cast<double>(one.recovery_history_ns) /
                                       (1e-9 * static_cast<double>(sim.scenario.imu_period_ns))));
  std::vector<double> t_one, t_three;
  std::uint64_t solutions_one = 0, solutions_three = 0;
  for (int p = 0; p < passes; ++p) {  // alternating: the machine's drift hits both alike
    t_one.push_back(pass(one, samples, warmup, true, solutions_one));
    t_three.push_back(pass(three, samples, warmup, false, solutions_three));
  }
  const double measured = static_cast<double>(samples.size() - warmup);
  const double us_one = 1e6 * median(t_one) / measured;
  const double us_three = 1e6 * median(t_three) / measured;
  const double per_extra = (us_three - us_one) / 2.0;
  std::printf(
      "filter lanes, seed 000 triplex samples (3 IMUs at 100 Hz, pseudoranges and fixes at 1 Hz), "
      "%zu IMU cycles after a %zu-cycle warm-up, median of %d passes:\n"
      "  one lane (unit 1 alone)  %.2f us per cycle\n"
      "  three lanes              %.2f us per cycle\n"
      "  each extra lane          %.2f us per cycle = %.2f x the single filter's (target <= 1)\n"
      "  solutions published: %llu and %llu per pass\n",
      samples.size() - warmup, warmup, passes, us_one, us_three, per_extra, per_extra / us_one,
      static_cast<unsigned long long>(solutions_one / static_cast<std::uint64_t>(passes)),
      static_cast<unsigned long long>(solutions_three / static_cast<std::uint64_t>(passes)));
  return 0;
}
