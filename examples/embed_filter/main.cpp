// The navbus filter pipeline inside your own Fast DDS participant. Nothing here is navbus's
// participant skeleton: the participant, topics, readers and writers are plain Fast DDS with
// the library's default QoS (plus reliability), as an avionics application would have them.
// navbus contributes the IDL types (navbus::types) and the DDS-free FilterPipeline
// (navbus::filter): you take samples, hand them to the pipeline, and publish what it returns.
//
// To stay self-contained the example also plays the IMU: it publishes 4 s of a stationary,
// levelled IMU at 100 Hz on navbus/imu/increment, and counts the solutions it receives back
// on navbus/nav/solution through a second reader. Usage: navbus_embed_filter_example [DOMAIN]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>
#include <navbus/bus/config.hpp>
#include <navbus/bus/health.hpp>
#include <navbus/core/math/earth.hpp>
#include <navbus/nav_filter/filter_config.hpp>
#include <navbus/nav_filter/filter_pipeline.hpp>

namespace fdds = eprosima::fastdds::dds;
namespace earth = navbus::core::earth;

namespace {

constexpr int kIncrements = 400;                  // 4 s at 100 Hz
constexpr std::uint32_t kPeriod_ns = 10'000'000;  // the configuration's inputs.imu.period_s
constexpr std::uint64_t kStart_ns = 1'400'000'000ull * 1'000'000'000ull;  // a GPS time

std::int64_t steadyNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

/// Increments of a perfect IMU at rest, levelled and pointing north, where the configuration's
/// initial_state puts it.
navbus::ImuIncrement stationaryIncrement(const navbus::nav_filter::FilterConfig& config, int k) {
  const double lat = config.engine.initial_state.position.latitude_rad;
  const Eigen::Vector3d g_ned =
      earth::gravityNed(lat, config.engine.initial_state.position.height_m);
  const Eigen::Vector3d w_ned(earth::kRotationRate_radps * std::cos(lat), 0.0,
                              -earth::kRotationRate_radps * std::sin(lat));
  const double dt_s = kPeriod_ns * 1e-9;
  navbus::ImuIncrement inc;
  inc.sensor_id(config.imu.id);
  inc.seq(static_cast<std::uint64_t>(k));
  inc.time_gps_ns(kStart_ns + static_cast<std::uint64_t>(k) * kPeriod_ns);
  inc.interval_ns(kPeriod_ns);
  for (int i = 0; i < 3; ++i) {
    inc.delta_vel_b_mps()[i] = -g_ned[i] * dt_s;
    inc.delta_angle_b_rad()[i] = w_ned[i] * dt_s;
  }
  return inc;
}

template <class PubSubType>
fdds::Topic* makeTopic(fdds::DomainParticipant* participant, const std::string& name) {
  fdds::TypeSupport type(new PubSubType());
  type.register_type(participant);
  return participant->create_topic(name, type.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
}

fdds::DataWriterQos reliableWriterQos() {
  fdds::DataWriterQos qos = fdds::DATAWRITER_QOS_DEFAULT;
  qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  qos.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
  return qos;
}

fdds::DataReaderQos reliableReaderQos() {
  fdds::DataReaderQos qos = fdds::DATAREADER_QOS_DEFAULT;
  qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  qos.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
  return qos;
}

bool waitForMatch(fdds::DataWriter* writer) {
  for (int i = 0; i < 100; ++i) {
    fdds::PublicationMatchedStatus status;
    writer->get_publication_matched_status(status);
    if (status.current_count > 0) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  const int domain = argc > 1 ? std::atoi(argv[1]) : 0;
  const navbus::nav_filter::FilterConfig config =
      navbus::nav_filter::parseFilterConfig(navbus::bus::loadYamlFile(NAVBUS_FILTER_CONFIG));

  // Your participant, with Fast DDS's defaults.
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  fdds::DomainParticipant* participant = factory->create_participant(
      static_cast<fdds::DomainId_t>(domain), fdds::PARTICIPANT_QOS_DEFAULT);
  if (participant == nullptr) {
    std::fprintf(stderr, "cannot create a participant on domain %d\n", domain);
    return 3;
  }
  fdds::Publisher* publisher = participant->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
  fdds::Subscriber* subscriber = participant->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
  fdds::Topic* imu_topic =
      makeTopic<navbus::ImuIncrementPubSubType>(participant, "navbus/imu/increment");
  fdds::Topic* solution_topic =
      makeTopic<navbus::NavigationSolutionPubSubType>(participant, "navbus/nav/solution");
  fdds::DataWriter* imu_writer = publisher->create_datawriter(imu_topic, reliableWriterQos());
  fdds::DataReader* imu_reader = subscriber->create_datareader(imu_topic, reliableReaderQos());
  fdds::DataWriter* solution_writer =
      publisher->create_datawriter(solution_topic, reliableWriterQos());
  fdds::DataReader* solution_reader =
      subscriber->create_datareader(solution_topic, reliableReaderQos());

  // The navbus filter pipeline: its solutions go to your writer.
  navbus::bus::HealthCounters health("my-avionics-app");
  navbus::nav_filter::FilterPipeline::Sinks sinks;
  sinks.solution = [&](const navbus::NavigationSolution& s) {
    navbus::NavigationSolution copy = s;
    solution_writer->write(&copy);
  };
  navbus::nav_filter::FilterPipeline pipeline(config, health, sinks);

  if (!waitForMatch(imu_writer) || !waitForMatch(solution_writer)) {
    std::fprintf(stderr, "the example's readers and writers did not match within 5 s\n");
    return 1;
  }
  for (int k = 1; k <= kIncrements; ++k) {
    navbus::ImuIncrement inc = stationaryIncrement(config, k);
    imu_writer->write(&inc);
  }

  // Your read loop: every increment taken goes to the pipeline.
  int taken = 0;
  const std::int64_t deadline_ns = steadyNowNs() + 10'000'000'000;
  while (taken < kIncrements && steadyNowNs() < deadline_ns) {
    navbus::ImuIncrement inc;
    fdds::SampleInfo info;
    while (imu_reader->take_next_sample(&inc, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      pipeline.onImu(inc);
      ++taken;
    }
    pipeline.pump(steadyNowNs());
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  pipeline.flush(steadyNowNs());  // end of input: release what the ordered merge still holds

  // Your subscriber of the solutions.
  int received = 0;
  navbus::NavigationSolution last;
  for (int idle_ms = 0; idle_ms < 1000; idle_ms += 10) {
    navbus::NavigationSolution s;
    fdds::SampleInfo info;
    while (solution_reader->take_next_sample(&s, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      last = s;
      ++received;
      idle_ms = 0;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const navbus::core::earth::Geodetic& start = config.engine.initial_state.position;
  navbus::core::earth::Geodetic end;
  end.latitude_rad = last.latitude_rad();
  end.longitude_rad = last.longitude_rad();
  end.height_m = last.height_m();
  const Eigen::Vector3d drift_ned_m = earth::differenceNed(end, start);
  std::printf("increments taken: %d of %d\n", taken, kIncrements);
  std::printf("solutions received by your subscriber: %d\n", received);
  std::printf(
      "last solution: seq %llu, %d increments used, drift from the start N E D %.3g %.3g "
      "%.3g m\n",
      static_cast<unsigned long long>(last.seq()), static_cast<int>(last.imu_samples_used()),
      drift_ned_m.x(), drift_ned_m.y(), drift_ned_m.z());
  std::printf("pipeline: %s\n", pipeline.summary().c_str());

  participant->delete_contained_entities();
  factory->delete_participant(participant);
  // 4 s of data at the configured 10 Hz solution rate.
  const bool ok = taken == kIncrements && received >= 39 && drift_ned_m.norm() < 0.05;
  return ok ? 0 : 1;
}
