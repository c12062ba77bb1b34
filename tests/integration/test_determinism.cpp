// The same sensor input, delivered with two different interleavings and pacings, gives a
// bit-identical solution stream (docs/architecture.md, the ordered merge).
#include <gtest/gtest.h>
#include <navbus_idl/NavigationPubSubTypes.h>

#include "harness.hpp"
#include "navbus/bus/conversions.hpp"
#include "navbus/records/formatters.hpp"
#include "navbus/sensor_sim/frame_publisher.hpp"
#include "navbus/sim/scenario_source.hpp"
#include "test_paths.hpp"

using namespace navbus;
using namespace std::chrono_literals;

namespace {

constexpr std::int64_t kStartNs = 1'400'000'000'000'000'000;  // an arbitrary whole-second GPS time
constexpr int kFrames = 500;                                  // 5 s at 100 Hz

std::vector<sim::SensorFrame> makeFrames() {
  sim::ScenarioConfig cfg;
  cfg.vehicle.position = {36.5 * M_PI / 180, 127.5 * M_PI / 180, 100.0};
  cfg.start_time_ns = kStartNs;
  cfg.imu.accel.random_walk = 50e-6 * 9.80665;
  cfg.imu.gyro.random_walk = 0.01 * M_PI / 180 / 60;
  cfg.imu.accel.bias = Eigen::Vector3d(1e-3, -2e-3, 5e-4);
  cfg.seed = 11;
  sim::ScenarioSource src(cfg);
  std::vector<sim::SensorFrame> frames;
  for (int k = 0; k < kFrames; ++k) frames.push_back(src.next());
  return frames;
}

enum class Delivery { kInTimeOrderSteady, kMeasurementsAheadImuInBursts };

struct Run {
  std::vector<std::string> solutions;  ///< CSV rows, 17 digits
  std::vector<std::string> diagnostics;
  bool tightly_coupled_reached{false};
};

Run runFilter(int domain, Delivery delivery, const std::vector<sim::SensorFrame>& frames,
              bool tightly_coupled) {
  const auto dir = test::scratchDir("determinism-" + std::to_string(domain));
  std::string yaml = test::filterConfig(domain);
  if (tightly_coupled) {
    yaml +=
        "mode: tightly_coupled\nekf: {accel_noise_ug_per_sqrthz: 50, gyro_arw_deg_per_sqrth: 0.01,"
        " initial_position_sigma_m: 10, accel_bias_sigma_ug: 1000}\n";
  }
  const std::string cfg = test::writeFile(dir / "filter.yaml", yaml);
  test::ChildProcess filter(navbus::test_paths::filterExe(), {"-c", cfg},
                            (dir / "filter.log").string());

  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(domain, "determinism-test"), shutdown);
  Run run;
  auto& solutions = run.solutions;
  me.subscribe<NavigationSolutionPubSubType>(
      bus::topic::kNavSolution, bus::profile::kSolutionReader,
      [&](const NavigationSolution& s, const auto&) {
        solutions.push_back(records::csvRows(s).at(0));
        run.tightly_coupled_reached =
            run.tightly_coupled_reached || s.mode() == MODE_TIGHTLY_COUPLED;
      });
  me.subscribe<FilterDiagnosticsPubSubType>(bus::topic::kFilterDiagnostics,
                                            bus::profile::kDiagnosticsReader,
                                            [&](const FilterDiagnostics& d, const auto&) {
                                              run.diagnostics.push_back(records::csvRows(d).at(0));
                                            });
  test::SensorInputWriters w(me);
  EXPECT_TRUE(test::spinUntil(me, 20s, [&] { return w.matched(); }));

  std::uint64_t n_imu = 0, n_obs = 0, n_fix = 0, n_star = 0;
  auto write_measurements = [&](const sim::SensorFrame& f) {
    if (f.has_gnss) {
      w.obs.write(sensor_sim::toIdl(f.gnss, 1, ++n_obs));
      w.fix.write(sensor_sim::toIdl(f.fix, 1, ++n_fix));
    }
    if (f.has_star_tracker) w.star.write(sensor_sim::toIdl(f.star_tracker, 1, ++n_star));
  };
  if (delivery == Delivery::kInTimeOrderSteady) {
    // One frame every 2 ms, each sample in time order.
    for (const auto& f : frames) {
      w.imu.write(bus::toIdl(f.increment, 1, ++n_imu));
      write_measurements(f);
      me.spinOnce(2ms);
    }
  } else {
    // Measurements up to 1.5 s ahead of the increments; increments in bursts of 37 with pauses.
    std::size_t next_measurement = 0;
    for (std::size_t k = 0; k < frames.size(); ++k) {
      while (next_measurement < frames.size() && next_measurement < k + 150)
        write_measurements(frames[next_measurement++]);
      w.imu.write(bus::toIdl(frames[k].increment, 1, ++n_imu));
      if (k % 37 == 36) me.spinOnce(30ms);
    }
  }
  // 5 s of data at 10 Hz: 50 solutions; wait for them, then a little longer for any extra.
  EXPECT_TRUE(test::spinUntil(me, 30s, [&] { return solutions.size() >= 50; }))
      << test::readFile(dir / "filter.log");
  test::spinUntil(me, 700ms, [] { return false; });
  filter.signal(SIGTERM);
  EXPECT_EQ(filter.wait(10s), 0);
  std::filesystem::remove_all(dir);
  return run;
}

}  // namespace

TEST(Determinism, TwoInterleavingsGiveBitIdenticalSolutions) {
  test::cleanSharedMemory();
  const auto frames = makeFrames();
  // Inertial-only (domains 72, 73) and tightly coupled, where the order of GNSS epochs relative to
  // the increments changes the estimate (domains 84, 85).
  for (const bool tc : {false, true}) {
    const auto a = runFilter(tc ? 84 : 72, Delivery::kInTimeOrderSteady, frames, tc);
    const auto b = runFilter(tc ? 85 : 73, Delivery::kMeasurementsAheadImuInBursts, frames, tc);
    ASSERT_EQ(a.solutions.size(), 50u);
    ASSERT_EQ(b.solutions.size(), a.solutions.size());
    // Rows print every double with 17 significant digits: equal text means equal bits.
    for (std::size_t i = 0; i < a.solutions.size(); ++i)
      EXPECT_EQ(a.solutions[i], b.solutions[i]) << "solution " << i;
    EXPECT_EQ(a.tightly_coupled_reached, tc);
    EXPECT_EQ(a.diagnostics.size(), tc ? 5u : 0u);  // one per GNSS epoch (1 Hz, 5 s)
    EXPECT_EQ(a.diagnostics, b.diagnostics);
    std::printf(
        "determinism (%s): %zu solutions and %zu diagnostics identical across both deliveries\n",
        tc ? "tightly coupled" : "inertial only", a.solutions.size(), a.diagnostics.size());
  }
  test::cleanSharedMemory();
}
