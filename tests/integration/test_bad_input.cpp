// A publisher sends NaN, infinite, out-of-order, duplicate, out-of-range and otherwise invalid
// samples among good ones: each is rejected and counted by reason in the filter's health, and
// the solution stays finite. A GNSS epoch with bad satellites (unknown id, one id twice, an
// implausible sigma) loses those satellites only: the good ones are fused (diagnostics rows).
// A hostile writer publishes payloads that are not ImuIncrements under the type's name (a bad
// encapsulation identifier, a truncated body): the filter drops and counts them (malformed)
// and goes on; before bus::GuardedType, the first one ended the filter process.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <vector>

#include <fastdds/dds/topic/TopicDataType.hpp>

#include <gtest/gtest.h>
#include <navbus_idl/HealthPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>

#include "harness.hpp"
#include "navbus/bus/conversions.hpp"
#include "navbus/bus/health.hpp"
#include "navbus/sensor_sim/frame_publisher.hpp"
#include "navbus/sim/scenario_source.hpp"
#include "test_paths.hpp"

using namespace navbus;
using namespace std::chrono_literals;

namespace {
constexpr int kDomain = 74;
using Counts = std::map<std::string, std::map<RejectReason, std::uint64_t>>;

/// Arbitrary bytes published under the name of navbus's ImuIncrement type (keyed, as the real
/// one, so that the filter's reader matches): what a faulty or hostile participant can send.
class RawBytesType : public eprosima::fastdds::dds::TopicDataType {
 public:
  using type = std::vector<unsigned char>;
  RawBytesType() {
    setName("navbus::ImuIncrement");
    m_typeSize = 1024;
    m_isGetKeyDefined = true;
  }
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
    const auto& bytes = *static_cast<type*>(data);
    if (bytes.size() > payload->max_size) return false;
    std::copy(bytes.begin(), bytes.end(), payload->data);
    payload->length = static_cast<std::uint32_t>(bytes.size());
    return true;
  }
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t*, void*) override { return false; }
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override {
    return [data] { return static_cast<std::uint32_t>(static_cast<type*>(data)->size()); };
  }
  void* createData() override { return new type(); }
  void deleteData(void* data) override { delete static_cast<type*>(data); }
  bool getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t* handle, bool) override {
    *handle = eprosima::fastrtps::rtps::InstanceHandle_t();
    handle->value[0] = 1;  // the key of sensor 1
    return true;
  }
};
}  // namespace

TEST(BadInput, RejectedByReasonCountedAndSolutionStaysFinite) {
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("bad-input");
  const std::string cfg =
      test::writeFile(dir / "filter.yaml", test::filterConfig(kDomain) + "mode: tightly_coupled\n");
  test::ChildProcess filter(navbus::test_paths::filterExe(), {"-c", cfg},
                            (dir / "filter.log").string());

  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(kDomain, "bad-input-test"), shutdown);
  std::vector<NavigationSolution> solutions;
  me.subscribe<NavigationSolutionPubSubType>(
      bus::topic::kNavSolution, bus::profile::kSolutionReader,
      [&](const NavigationSolution& s, const auto&) { solutions.push_back(s); });
  std::vector<FilterDiagnostics> diagnostics;
  me.subscribe<FilterDiagnosticsPubSubType>(
      bus::topic::kFilterDiagnostics, bus::profile::kDiagnosticsReader,
      [&](const FilterDiagnostics& d, const auto&) { diagnostics.push_back(d); });
  Health filter_health;
  me.subscribe<HealthPubSubType>(bus::topic::kHealth, bus::profile::kHealthReader,
                                 [&](const Health& h, const auto&) {
                                   if (h.participant().to_string() == "navbus-filter")
                                     filter_health = h;
                                 });
  test::SensorInputWriters w(me);
  bus::ShutdownSignal hostile_shutdown;
  bus::Participant hostile(test::testParticipant(kDomain, "hostile-writer"), hostile_shutdown);
  auto garbage =
      hostile.createWriter<RawBytesType>(bus::topic::kImuIncrement, bus::profile::kSensorWriter);
  ASSERT_TRUE(
      test::spinUntil(me, 20s, [&] { return w.matched() && garbage.matchedReaders() >= 1; }));

  sim::ScenarioSource src = test::testScenarioSource();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  std::uint64_t seq = 0, n_obs = 0, n_fix = 0, n_star = 0;
  std::vector<int> good_svs;  // of the epoch with bad satellites added
  std::uint64_t screened_epoch_ns = 0;
  ImuIncrement last;
  for (int k = 0; k < 300; ++k) {
    const sim::SensorFrame f = src.next();
    const ImuIncrement good = bus::toIdl(f.increment, 1, ++seq);
    ImuIncrement bad = good;  // bad samples carry the seq of the good one that follows them
    switch (k) {
      case 20:
        bad.delta_vel_b_mps()[1] = nan;
        w.imu.write(bad);
        break;
      case 40:
        bad.delta_angle_b_rad()[2] = inf;
        w.imu.write(bad);
        break;
      case 60:
        bad.delta_vel_b_mps()[0] = 50.0;
        w.imu.write(bad);
        break;  // 5000 m/s^2
      case 80:
        bad.interval_ns(0);
        w.imu.write(bad);
        break;
      case 100:
        bad.time_gps_ns(last.time_gps_ns() - 5'000'000);
        w.imu.write(bad);
        break;  // out of order
      case 120:
        w.imu.write(last);
        break;  // duplicate
      case 140:
        bad.sensor_id(9);
        w.imu.write(bad);
        break;  // not configured
      case 160:
        bad.time_gps_ns(good.time_gps_ns() + 3'600'000'000'000ULL);
        w.imu.write(bad);
        break;   // an hour in the future: not adopted, the genuine samples after it go on
      case 180:  // encapsulation identifier 0x000a: Fast-CDR throws BadParamException
        garbage.write({0x00, 0x0a, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00});
        break;
      case 200:  // a valid header and a body cut short after the sensor id
        garbage.write({0x00, 0x01, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00});
        break;
      default:
        break;
    }
    w.imu.write(good);
    last = good;
    if (f.has_gnss) {
      auto e = sensor_sim::toIdl(f.gnss, 1, ++n_obs);
      if (n_obs == 2) {
        // Bad satellites beside the good ones: an unknown id, the last satellite twice (both
        // copies go: which is right cannot be told), a sigma of 1e-300 m on a copy of the first.
        auto& sats = e.satellites();
        ASSERT_GE(sats.size(), 5u);
        for (std::size_t i = 0; i + 1 < sats.size(); ++i) good_svs.push_back(sats[i].sv_id());
        good_svs.erase(good_svs.begin());  // the first gets an implausible twin below
        auto unknown = sats[1];
        unknown.sv_id(40);
        auto twin = sats.back();
        twin.pseudorange_m(twin.pseudorange_m() + 100.0);
        sats.push_back(twin);
        sats.push_back(unknown);
        sats[0].pseudorange_sigma_m(1e-300);
        screened_epoch_ns = e.time_gps_ns();
      }
      w.obs.write(e);
      w.fix.write(sensor_sim::toIdl(f.fix, 1, ++n_fix));
      if (n_obs == 1) {
        w.obs.write(e);  // the same epoch again: a duplicate sample
        auto x = sensor_sim::toIdl(f.fix, 1, n_fix + 1);
        x.latitude_rad(nan);
        w.fix.write(x);
      }
    }
    if (f.has_star_tracker) {
      w.star.write(sensor_sim::toIdl(f.star_tracker, 1, ++n_star));
      if (n_star == 2) {
        auto s = sensor_sim::toIdl(f.star_tracker, 1, n_star + 1);
        s.q_b_to_i()[1] += 0.01;
        w.star.write(s);
      }
    }
    me.spinOnce(1ms);
  }

  auto counts = [&] {
    Counts c;
    for (const auto& in : filter_health.inputs()) {
      for (const auto& r : in.rejected()) c[in.topic().to_string()][r.reason()] = r.count();
    }
    return c;
  };
  auto stream = [&](const std::string& topic) -> const StreamHealth* {
    for (const auto& in : filter_health.inputs())
      if (in.topic().to_string() == topic) return &in;
    return nullptr;
  };
  const Counts expected = {
      {bus::topic::kImuIncrement,
       {{REJECT_NOT_FINITE, 2},
        {REJECT_OUT_OF_RANGE, 1},
        {REJECT_BAD_INTERVAL, 1},
        {REJECT_TIME_NOT_MONOTONIC, 1},
        {REJECT_DUPLICATE, 1},
        {REJECT_UNEXPECTED_SOURCE, 1},
        {REJECT_TIME_JUMP, 1},
        {REJECT_MALFORMED, 2}}},
      {bus::topic::kGnssObservations, {{REJECT_DUPLICATE, 1}}},
      {bus::topic::kGnssFix, {{REJECT_NOT_FINITE, 1}}},
      {bus::topic::kStarTracker, {{REJECT_BAD_QUATERNION, 1}}},
  };
  ASSERT_TRUE(test::spinUntil(me, 20s, [&] {
    const auto* s = stream(bus::topic::kImuIncrement);
    return s != nullptr && s->received() == 310 && counts() == expected && solutions.size() >= 30;
  })) << test::readFile(dir / "filter.log");
  const auto* s = stream(bus::topic::kImuIncrement);
  EXPECT_EQ(s->accepted(), 300u);
  EXPECT_EQ(s->sequence_gaps(), 0u);
  for (const auto& [topic, reasons] : counts()) {
    for (const auto& [reason, n] : reasons)
      std::printf("rejected on %s: %s x%llu\n", topic.c_str(), bus::rejectReasonName(reason),
                  static_cast<unsigned long long>(n));
  }
  // The screened epoch: accepted, its bad satellites counted by reason, the good ones fused.
  const auto* obs = stream(bus::topic::kGnssObservations);
  ASSERT_NE(obs, nullptr);
  std::map<RejectReason, std::uint64_t> dropped;
  for (const auto& r : obs->elements_rejected()) dropped[r.reason()] = r.count();
  const std::map<RejectReason, std::uint64_t> expected_dropped = {
      {REJECT_OUT_OF_RANGE, 1}, {REJECT_DUPLICATE_SATELLITE, 2}, {REJECT_UNKNOWN_SATELLITE, 1}};
  EXPECT_EQ(dropped, expected_dropped);
  EXPECT_EQ(obs->accepted(), n_obs);
  const auto diag = std::find_if(diagnostics.begin(), diagnostics.end(), [&](const auto& d) {
    return d.time_gps_ns() == screened_epoch_ns;
  });
  ASSERT_NE(diag, diagnostics.end()) << "no diagnostics for the screened epoch";
  std::set<int> fused;
  for (const auto& row : diag->rows())
    if (row.sv_id() != 0) fused.insert(row.sv_id());
  EXPECT_EQ(fused, std::set<int>(good_svs.begin(), good_svs.end()));
  std::printf(
      "screened epoch: %zu satellites kept, dropped: unknown id 1, duplicate id 2, "
      "implausible sigma 1\n",
      fused.size());
  EXPECT_EQ(solutions.size(), 30u);
  for (const auto& sol : solutions) {
    EXPECT_TRUE(std::isfinite(sol.latitude_rad()) && std::isfinite(sol.longitude_rad()) &&
                std::isfinite(sol.height_m()) && std::isfinite(sol.roll_rad()) &&
                std::isfinite(sol.yaw_rad()));
    for (double v : sol.vel_ned_mps()) EXPECT_TRUE(std::isfinite(v));
    // Tightly coupled on a handful of 3 m pseudoranges: the height is the GNSS one, metres off.
    EXPECT_LT(std::abs(sol.height_m() - 100.0), 15.0);
  }
  filter.signal(SIGTERM);
  EXPECT_EQ(filter.wait(10s), 0);
  std::filesystem::remove_all(dir);
  test::cleanSharedMemory();
}
