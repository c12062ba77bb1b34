#include "navbus/tool/replay.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>

#include <spdlog/spdlog.h>

#include "navbus/bus/app.hpp"
#include "navbus/bus/stream_end.hpp"
#include "navbus/bus/streams.hpp"
#include "navbus/records/csv_messages.hpp"
#include "navbus/records/mcap.hpp"
#include "navbus/records/mcap_samples.hpp"
#include "navbus/records/recording_layout.hpp"
#include "navbus/tool/spin.hpp"
#include "navbus/tool/topic_registry.hpp"

namespace navbus::tool {

namespace {

using Clock = std::chrono::steady_clock;
constexpr const char* kSourceTimeColumn = "source_timestamp_ns";

// The data time of a sample: when its (last) measurement is valid [ns, GPS time].
std::int64_t dataTimeNs(const ImuIncrement& m) {
  return static_cast<std::int64_t>(m.time_gps_ns());
}
std::int64_t dataTimeNs(const ImuIncrementBlock& m) {
  return m.increments().empty() ? 0 : dataTimeNs(m.increments().back());
}
std::int64_t dataTimeNs(const ImuRawBlock& m) {
  const auto n = static_cast<std::int64_t>(m.samples().size());
  return static_cast<std::int64_t>(m.first_sample_time_gps_ns()) +
         std::max<std::int64_t>(n - 1, 0) * static_cast<std::int64_t>(m.sample_period_ns());
}
std::int64_t dataTimeNs(const GnssObservationEpochBlock& m) {
  return static_cast<std::int64_t>(bus::newestElementTimeGpsNs(m));
}
std::int64_t dataTimeNs(const GnssFixBlock& m) {
  return static_cast<std::int64_t>(bus::newestElementTimeGpsNs(m));
}
std::int64_t dataTimeNs(const StarTrackerAttitudeBlock& m) {
  return static_cast<std::int64_t>(bus::newestElementTimeGpsNs(m));
}
template <class T>
std::int64_t dataTimeNs(const T& m) {
  return static_cast<std::int64_t>(m.time_gps_ns());
}

/// One recorded topic: its messages, their pacing times, and its writer.
class Stream {
 public:
  virtual ~Stream() = default;
  virtual const std::string& topic() const = 0;
  virtual std::size_t size() const = 0;
  /// Pacing time of message i [ns]: its source time stamp, or its data time.
  virtual std::int64_t paceNs(std::size_t i, bool source_times) const = 0;
  virtual bool hasSourceTimes() const = 0;
  virtual void open(bus::Participant& p) = 0;
  virtual std::size_t matchedReaders() const = 0;
  /// Writes message i, waiting for a reader that fell behind (bus::Writer); false if it was
  /// not written (the replay stops, or no reader is left).
  virtual bool publish(std::size_t i, const std::function<bool()>& stopping) = 0;
  /// Writes retried because a reliable reader had not acknowledged within max_blocking_time.
  virtual std::uint64_t writeWaits() const = 0;
  /// Disposes every instance it wrote (end of stream) and waits for the readers' acknowledgments,
  /// for as long as a reader is matched and `stopping()` is false.
  virtual void end(const std::function<bool()>& stopping) = 0;
};

template <class PubSubType>
class TypedStream : public Stream {
 public:
  using T = typename PubSubType::type;
  /// `source_ns`: one per message, or empty when the recording has no source time stamps.
  TypedStream(std::string topic, std::string profile, std::vector<T> messages,
              std::vector<std::int64_t> source_ns)
      : topic_(std::move(topic)),
        profile_(std::move(profile)),
        messages_(std::move(messages)),
        source_ns_(std::move(source_ns)) {}
  const std::string& topic() const override { return topic_; }
  std::size_t size() const override { return messages_.size(); }
  std::int64_t paceNs(std::size_t i, bool source_times) const override {
    return source_times ? source_ns_[i] : dataTimeNs(messages_[i]);
  }
  bool hasSourceTimes() const override { return !source_ns_.empty() || messages_.empty(); }
  void open(bus::Participant& p) override {
    writer_ = p.createWriter<PubSubType>(topic_, profile_);
  }
  std::size_t matchedReaders() const override { return writer_.matchedReaders(); }
  bool publish(std::size_t i, const std::function<bool()>& stopping) override {
    return writer_.writeWaitingForReaders(messages_[i], stopping, write_waits_);
  }
  std::uint64_t writeWaits() const override { return write_waits_; }
  void end(const std::function<bool()>& stopping) override {
    // Every instance the stream wrote ends: on a keyed topic each sensor's (each unit of a
    // redundant set), with its last message, in the order the instances fell silent.
    std::vector<eprosima::fastrtps::rtps::InstanceHandle_t> ended;
    std::vector<std::size_t> last;
    PubSubType type;
    for (std::size_t i = messages_.size(); i-- > 0;) {
      eprosima::fastrtps::rtps::InstanceHandle_t key;
      type.getKey(&messages_[i], &key);
      if (std::find(ended.begin(), ended.end(), key) != ended.end()) continue;
      ended.push_back(key);
      last.push_back(i);
    }
    // A reader far behind (a fault manager under a sanitizer: more than 10 s) holds the
    // writer's history full: the disposes wait for it as the samples did, and the replay
    // leaves only once they are acknowledged. Leaving earlier, its readers saw the writers
    // gone before the ends and judged every unit lost.
    for (auto i = last.rbegin(); i != last.rend(); ++i)
      writer_.disposeWaitingForReaders(messages_[*i], stopping);
    if (!last.empty()) writer_.waitForAcknowledgments(stopping);
  }

 private:
  std::string topic_, profile_;
  std::vector<T> messages_;
  std::vector<std::int64_t> source_ns_;
  bus::Writer<T> writer_;
  std::uint64_t write_waits_{0};
};

/// The recorded source time stamps of a CSV table's messages (empty without the column).
std::vector<std::int64_t> csvSourceTimes(
    const records::CsvTable& table,
    const std::vector<std::pair<std::size_t, std::size_t>>& ranges) {
  std::vector<std::int64_t> source_ns;
  if (!table.has(kSourceTimeColumn)) return source_ns;
  const std::size_t column = table.column(kSourceTimeColumn);
  for (const auto& [first, count] : ranges) {
    const std::string& cell = table.rows[first][column];
    std::int64_t ns = 0;
    const auto [ptr, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), ns);
    if (ec != std::errc() || ptr != cell.data() + cell.size()) {
      throw bus::ConfigError(table.file + " line " + std::to_string(first + 2) + " column '" +
                             kSourceTimeColumn + "': '" + cell + "' is not a valid number");
    }
    source_ns.push_back(ns);
  }
  return source_ns;
}

/// Calls `f(traits_tag)` for the sensor message type published on `topic`.
template <class F>
void forSensorTopic(const std::string& topic, F&& f) {
  bus::forEachSensorMessage([&](auto tag) {
    using Traits = bus::SensorMessage<typename decltype(tag)::type>;
    if (topic == Traits::kTopic.topic) f(Traits{});
  });
}

std::unique_ptr<Stream> loadCsvStream(const std::string& topic, const std::filesystem::path& file) {
  const records::CsvTable table = records::readCsv(file);
  std::unique_ptr<Stream> stream;
  forSensorTopic(topic, [&](auto traits) {
    using Traits = decltype(traits);
    using T = typename Traits::PubSubType::type;
    const auto ranges = records::messageRowRanges(table);
    stream = std::make_unique<TypedStream<typename Traits::PubSubType>>(
        topic, Traits::kTopic.writer_profile, records::parseMessages<T>(table, ranges),
        csvSourceTimes(table, ranges));
  });
  return stream;
}

/// A recorded channel's messages decoded with the topic's type.
std::unique_ptr<Stream> loadMcapStream(const std::string& file, const std::string& topic,
                                       const records::McapContents& contents,
                                       const records::McapChannel& channel) {
  std::unique_ptr<Stream> stream;
  forSensorTopic(topic, [&](auto traits) {
    using Traits = decltype(traits);
    using PubSubType = typename Traits::PubSubType;
    std::vector<std::int64_t> source_ns;
    auto decoded = records::decodeChannel<PubSubType>(file, contents, channel, &source_ns);
    stream = std::make_unique<TypedStream<PubSubType>>(topic, Traits::kTopic.writer_profile,
                                                       std::move(decoded), std::move(source_ns));
  });
  return stream;
}

void checkReplayable(const ReplayOptions& o) {
  const auto& replayable = replayableTopics();
  for (const auto& t : o.topics) {
    if (std::find(replayable.begin(), replayable.end(), t) == replayable.end()) {
      std::string known;
      for (const auto& r : replayable) known += " " + r;
      throw bus::ConfigError("topic '" + t + "' cannot be replayed; replayable topics:" + known);
    }
  }
}

std::vector<std::unique_ptr<Stream>> loadCsvStreams(const ReplayOptions& o) {
  std::vector<std::unique_ptr<Stream>> streams;
  for (const auto& topic : o.topics.empty() ? replayableTopics() : o.topics) {
    const std::filesystem::path file =
        std::filesystem::path(o.recording) / records::recordFileName(topic);
    if (!std::filesystem::exists(file)) {
      if (!o.topics.empty()) throw bus::ConfigError(file.string() + ": no such file");
      continue;
    }
    streams.push_back(loadCsvStream(topic, file));
    spdlog::info("{}: {} samples of {}", file.string(), streams.back()->size(), topic);
  }
  return streams;
}

std::vector<std::unique_ptr<Stream>> loadMcapStreams(const ReplayOptions& o) {
  const records::McapContents contents = records::readMcap(o.recording);
  if (contents.cut) {
    spdlog::warn("{}; replaying the {} messages read (navbus recover closes the file)",
                 records::describeCut(o.recording, *contents.cut), contents.messages.size());
  }
  std::vector<std::unique_ptr<Stream>> streams;
  for (const auto& topic : o.topics.empty() ? replayableTopics() : o.topics) {
    const records::McapChannel* channel = records::channelOfTopic(contents, topic);
    if (channel == nullptr) {
      if (!o.topics.empty()) {
        throw bus::ConfigError(o.recording + ": no channel of topic '" + topic + "'");
      }
      continue;
    }
    streams.push_back(loadMcapStream(o.recording, topic, contents, *channel));
    spdlog::info("{}: {} samples of {}", o.recording, streams.back()->size(), topic);
  }
  return streams;
}

std::vector<std::unique_ptr<Stream>> loadStreams(const ReplayOptions& o) {
  checkReplayable(o);
  const bool mcap = std::filesystem::is_regular_file(o.recording);
  if (mcap && !records::isMcapFile(o.recording)) {
    throw bus::ConfigError(o.recording +
                           ": neither a directory of CSV files nor an MCAP file (no MCAP magic)");
  }
  std::vector<std::unique_ptr<Stream>> streams = mcap ? loadMcapStreams(o) : loadCsvStreams(o);
  // A topic without samples has no reader to wait for.
  streams.erase(
      std::remove_if(streams.begin(), streams.end(), [](const auto& s) { return s->size() == 0; }),
      streams.end());
  if (streams.empty()) {
    throw bus::ConfigError("no recording of a sensor topic in '" + o.recording +
                           "' (navbus record writes navbus_imu_increment.csv, ..., or one MCAP "
                           "file with --format mcap)");
  }
  return streams;
}

/// Readers to wait for per topic: 1, or what --min-readers TOPIC=N says.
std::map<std::string, std::size_t> minReaders(const ReplayOptions& o) {
  std::map<std::string, std::size_t> wanted;
  for (const auto& t : replayableTopics()) wanted[t] = 1;
  for (const std::string& entry : o.min_readers) {
    const std::size_t eq = entry.find('=');
    std::size_t n = 0;
    const char* end = entry.data() + entry.size();
    const auto parsed = eq == std::string::npos
                            ? std::from_chars_result{end, std::errc::invalid_argument}
                            : std::from_chars(entry.data() + eq + 1, end, n);
    if (parsed.ec != std::errc() || parsed.ptr != end || n > 64 ||
        wanted.count(entry.substr(0, eq)) == 0) {
      throw bus::ConfigError("--min-readers '" + entry +
                             "': expected TOPIC=N with a replayable topic and N in 0..64");
    }
    wanted[entry.substr(0, eq)] = n;
  }
  return wanted;
}

struct Event {
  std::int64_t pace_ns;
  std::size_t stream, index;
};

/// Every sample of every stream in pacing order (a stable sort keeps each file's order).
std::vector<Event> schedule(const std::vector<std::unique_ptr<Stream>>& streams,
                            bool source_times) {
  std::vector<Event> events;
  for (std::size_t s = 0; s < streams.size(); ++s) {
    for (std::size_t i = 0; i < streams[s]->size(); ++i) {
      events.push_back({streams[s]->paceNs(i, source_times), s, i});
    }
  }
  std::stable_sort(events.begin(), events.end(),
                   [](const Event& a, const Event& b) { return a.pace_ns < b.pace_ns; });
  return events;
}

}  // namespace

const std::vector<std::string>& replayableTopics() {
  static const std::vector<std::string> topics = [] {
    std::vector<std::string> t;
    for (const bus::SensorTopic& row : bus::kSensorTopics) t.emplace_back(row.topic);
    return t;
  }();
  return topics;
}

int runReplayCommand(const bus::Participant::Options& participant, const ReplayOptions& o,
                     bus::ShutdownSignal& shutdown) {
  if (!(o.speed >= 0.0)) {
    throw bus::ConfigError("--speed " + std::to_string(o.speed) + " must be >= 0");
  }
  const std::map<std::string, std::size_t> min_readers = minReaders(o);
  auto streams = loadStreams(o);
  if (o.pace != "data" && o.pace != "source") {
    throw bus::ConfigError("--pace '" + o.pace + "' must be data or source");
  }
  const bool source_times = o.pace == "source";
  for (const auto& s : streams) {
    if (source_times && !s->hasSourceTimes()) {
      throw bus::ConfigError("--pace source: the recording of " + s->topic() + " has no " +
                             kSourceTimeColumn + " column");
    }
  }
  spdlog::info("pacing by {} at speed {}",
               source_times ? "the recorded source time stamps" : "the samples' data times",
               o.speed);
  const std::vector<Event> events = schedule(streams, source_times);

  bus::Participant p(participant, shutdown);
  for (auto& s : streams) s->open(p);
  const auto matched = [&](const Stream& s) {
    return s.matchedReaders() >= min_readers.at(s.topic());
  };
  const auto all_matched = [&] {
    return std::all_of(streams.begin(), streams.end(), [&](const auto& s) { return matched(*s); });
  };
  if (!spinUntil(p, o.match_timeout_s, all_matched)) {
    for (const auto& s : streams) {
      if (!matched(*s)) {
        spdlog::error("{} of {} readers of {} within {} s", s->matchedReaders(),
                      min_readers.at(s->topic()), s->topic(), o.match_timeout_s);
      }
    }
    p.finish();
    return bus::kExitRuntimeError;
  }
  const bool waited =
      std::any_of(min_readers.begin(), min_readers.end(),
                  [](const auto& topic_readers) { return topic_readers.second > 0; });
  if (waited) p.spinFor(bus::kStartSettle);  // the readers' side of the match

  std::vector<std::uint64_t> published(streams.size(), 0);
  const auto start = Clock::now();
  for (const Event& e : events) {
    if (p.stopping()) break;
    if (o.speed > 0.0) {
      const auto due =
          start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                      1e-9 * static_cast<double>(e.pace_ns - events.front().pace_ns) / o.speed));
      while (Clock::now() < due && !p.stopping()) p.spinOnce(due - Clock::now());
    }
    if (streams[e.stream]->publish(e.index, [&p] { return p.stopping(); })) ++published[e.stream];
  }
  for (auto& s : streams) s->end([&p] { return p.stopping(); });
  if (!p.stopping()) p.announceDataEnded();  // also in its health: reliable for every reader
  const double elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
  if (!p.stopping()) p.spinFor(bus::kEndOfStreamLinger);  // the ends reach best-effort readers
  bool complete = true;
  for (std::size_t s = 0; s < streams.size(); ++s) {
    spdlog::info("replayed {} of {} samples of {} (writes that waited for a reader behind: {})",
                 published[s], streams[s]->size(), streams[s]->topic(), streams[s]->writeWaits());
    complete = complete && published[s] == streams[s]->size();
  }
  const double span_s =
      events.empty() ? 0.0
                     : 1e-9 * static_cast<double>(events.back().pace_ns - events.front().pace_ns);
  spdlog::info("{:.3f} s of recording in {:.3f} s", span_s, elapsed_s);
  p.finish();
  return complete ? bus::kExitOk : bus::kExitRuntimeError;
}

}  // namespace navbus::tool
