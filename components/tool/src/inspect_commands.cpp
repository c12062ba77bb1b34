// `navbus topics`, `echo` and `record`: what is on the bus, one topic's samples, every
// chosen topic into CSV files or one MCAP file.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>

#include <spdlog/spdlog.h>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>

#include "navbus/bus/app.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/tool/record_sinks.hpp"
#include "navbus/tool/topic_registry.hpp"
#include "subcommand.hpp"

namespace nb = navbus;
namespace fdds = eprosima::fastdds::dds;

namespace navbus::tool::cli {
namespace {

/// Collects discovered writers and readers by GUID.
class DiscoveryListener : public fdds::DomainParticipantListener {
 public:
  struct Endpoints {
    std::string type;
    std::set<std::string> writers, readers;
  };
  void on_publisher_discovery(fdds::DomainParticipant*,
                              eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override {
    update(info.info.topicName().to_string(), info.info.typeName().to_string(),
           guid(info.info.guid()), true,
           info.status == eprosima::fastrtps::rtps::WriterDiscoveryInfo::REMOVED_WRITER);
  }
  void on_subscriber_discovery(fdds::DomainParticipant*,
                               eprosima::fastrtps::rtps::ReaderDiscoveryInfo&& info) override {
    update(info.info.topicName().to_string(), info.info.typeName().to_string(),
           guid(info.info.guid()), false,
           info.status == eprosima::fastrtps::rtps::ReaderDiscoveryInfo::REMOVED_READER);
  }
  std::map<std::string, Endpoints> snapshot() {
    std::lock_guard<std::mutex> lock(mutex_);
    return topics_;
  }

 private:
  static std::string guid(const eprosima::fastrtps::rtps::GUID_t& g) {
    std::ostringstream out;
    out << g;
    return out.str();
  }
  void update(const std::string& topic, const std::string& type, const std::string& id, bool writer,
              bool removed) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto& e = topics_[topic];
    e.type = type;
    auto& set = writer ? e.writers : e.readers;
    if (removed)
      set.erase(id);
    else
      set.insert(id);
  }
  std::mutex mutex_;
  std::map<std::string, Endpoints> topics_;
};

/// Prints samples as text blocks or CSV lines.
class EchoSink : public SampleSink {
 public:
  EchoSink(bool csv, const std::string& header, std::uint64_t limit) : csv_(csv), limit_(limit) {
    if (csv_) std::cout << header << "\n";
  }
  void onSample(const std::string& topic, const SampleTimes&, const SampleViews& sample) override {
    if (limit_ > 0 && count_ >= limit_) return;  // one dispatch round may hold more samples
    ++count_;
    if (csv_) {
      for (const auto& r : sample.csv_rows()) std::cout << r << "\n";
    } else {
      std::cout << "--- " << topic << " #" << count_ << "\n" << sample.text();
    }
    std::cout.flush();
  }
  std::uint64_t count() const { return count_; }

 private:
  bool csv_;
  std::uint64_t limit_;
  std::uint64_t count_{0};
};

const TopicEntry& requireTopic(const std::string& name) {
  const auto* e = findTopic(name);
  if (e == nullptr) {
    std::string known;
    for (const auto& t : topicRegistry()) known += " " + t.name;
    throw nb::bus::ConfigError("unknown topic '" + name + "'; navbus topics are:" + known);
  }
  return *e;
}

/// Runs the participant until `done()` or `duration_s` (0: until SIGINT/SIGTERM).
void runFor(nb::bus::Participant& p, double duration_s, const std::function<bool()>& done) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration_s);
  while (!p.stopping() && !done() &&
         (duration_s <= 0.0 || std::chrono::steady_clock::now() < end)) {
    p.spinOnce(std::chrono::milliseconds(50));
  }
  p.finish();
}

class TopicsCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.add_subcommand("topics",
                              "list the topics seen on the bus with their writers and readers");
    cli_->add_option("--wait", wait_s, "seconds of discovery before printing")
        ->check(CLI::Range(0.1, 600.0));
  }
  bool inspectsBus() const override { return true; }
  int run(bus::Participant::Options& options, bus::ShutdownSignal& shutdown) override {
    DiscoveryListener listener;
    options.dds.listener = &listener;
    nb::bus::Participant p(options, shutdown);
    runFor(p, wait_s, [] { return false; });
    std::printf("%-30s %-36s %8s %8s\n", "TOPIC", "TYPE", "WRITERS", "READERS");
    for (const auto& [topic, e] : listener.snapshot()) {
      std::printf("%-30s %-36s %8zu %8zu\n", topic.c_str(), e.type.c_str(), e.writers.size(),
                  e.readers.size());
    }
    return nb::bus::kExitOk;
  }

 private:
  double wait_s{2.0};
};

class EchoCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.add_subcommand("echo", "print the samples of one topic");
    cli_->add_option("topic", echo_topic, "topic name, e.g. navbus/nav/solution")->required();
    cli_->add_flag("--csv", echo_csv, "CSV instead of text");
    cli_->add_option("-n,--count", count, "stop after this many samples (exit 1 if not reached)");
    cli_->add_option("--duration", duration_s, "stop after this many seconds (0: until SIGINT)");
  }
  bool inspectsBus() const override { return true; }
  int run(bus::Participant::Options& options, bus::ShutdownSignal& shutdown) override {
    const auto& entry = requireTopic(echo_topic);
    nb::bus::Participant p(options, shutdown);
    EchoSink sink(echo_csv, entry.csv_header, count);
    entry.subscribe(p, sink);
    runFor(p, duration_s, [&] { return count > 0 && sink.count() >= count; });
    return (count > 0 && sink.count() < count) ? nb::bus::kExitRuntimeError : nb::bus::kExitOk;
  }

 private:
  std::string echo_topic;
  bool echo_csv{false};
  std::uint64_t count{0};
  double duration_s{0.0};
};

/// Says when the number of writers matched to a recorded topic changes, so that a user (or a
/// test) knows from when on a topic's samples are recorded: readers are volatile, so what a
/// writer published before it matched the recorder is not in the recording.
class WriterMatchLog {
 public:
  void add(const std::string& topic, eprosima::fastdds::dds::DataReader* reader) {
    readers_.push_back({topic, reader, 0});
  }
  void update() {
    for (auto& r : readers_) {
      eprosima::fastdds::dds::SubscriptionMatchedStatus status;
      r.reader->get_subscription_matched_status(status);
      if (status.current_count == r.writers) continue;
      r.writers = status.current_count;
      spdlog::info("{}: {} writer(s) matched", r.topic, r.writers);
    }
  }

 private:
  struct Matched {
    std::string topic;
    eprosima::fastdds::dds::DataReader* reader;
    std::int32_t writers;
  };
  std::vector<Matched> readers_;
};

class RecordCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.add_subcommand("record",
                              "record topics into CSV files, one per topic, or into one MCAP file");
    cli_->add_option("topics", record_topics, "topic names");
    cli_->add_flag("--all", record_all, "every navbus topic");
    cli_->add_option("-o,--out", out, "csv: the output directory (created); mcap: the output file")
        ->required();
    cli_->add_option("--format", format,
                     "csv: a file per topic (navbus replay, offline); mcap: one MCAP file, a "
                     "channel per topic with its schema and the samples' CDR bytes (Foxglove, "
                     "the mcap CLI, navbus replay)")
        ->check(CLI::IsMember({"csv", "mcap"}));
    cli_->add_option("-n,--count", count,
                     "stop when every topic has this many samples (exit 1 if not reached)");
    cli_->add_option("--idle", idle_s,
                     "stop once no sample of any topic came for this many seconds after the "
                     "first (0: never)")
        ->check(CLI::Range(0.0, 3600.0));
    cli_->add_option("--duration", duration_s, "stop after this many seconds (0: until SIGINT)");
    cli_->add_option("--flush-s", flush_s,
                     "put what was recorded on the disk at least this often (mcap: the open "
                     "chunk closed and the file synced; csv: every file flushed), so that a "
                     "killed recorder loses at most this much; navbus recover closes such a file")
        ->check(CLI::Range(0.05, 3600.0));
    cli_->add_flag("--foxglove", foxglove,
                   "mcap: add the channels in Foxglove's schemas derived from the recorded "
                   "topics (navbus/foxglove/location_fix from the solution for the Map panel, "
                   "navbus/foxglove/log from decisions, commands and their outcomes)");
  }
  bool inspectsBus() const override { return true; }
  int run(bus::Participant::Options& options, bus::ShutdownSignal& shutdown) override {
    std::unique_ptr<RecordSink> sink_owner;
    if (format == "mcap") {
      const auto parent = std::filesystem::path(out).parent_path();
      if (!parent.empty()) std::filesystem::create_directories(parent);
      sink_owner = std::make_unique<McapRecordSink>(out, options.dds.ros2_names, foxglove);
    } else if (foxglove) {
      throw nb::bus::ConfigError("record: --foxglove needs --format mcap (format is '" + format +
                                 "')");
    } else {
      sink_owner = std::make_unique<CsvRecordSink>(out);
    }
    RecordSink& sink = *sink_owner;
    nb::bus::Participant p(options, shutdown);
    std::vector<const TopicEntry*> entries;
    if (record_all) {
      for (const auto& t : topicRegistry()) record_topics.push_back(t.name);
    }
    if (record_topics.empty()) {
      throw nb::bus::ConfigError("record: name the topics, or --all");
    }
    WriterMatchLog matches;
    for (const auto& t : record_topics) {
      entries.push_back(&requireTopic(t));
      sink.open(*entries.back());
      matches.add(t, entries.back()->subscribe(p, sink));
    }
    auto last_flush = std::chrono::steady_clock::now();
    auto all_counted = [&] {
      matches.update();
      const auto now = std::chrono::steady_clock::now();
      if (now - last_flush >= std::chrono::duration<double>(flush_s)) {
        sink.flush();
        last_flush = now;
      }
      if (idle_s > 0.0 && sink.idleSeconds() >= idle_s) return true;
      if (count == 0) return false;
      for (const auto* e : entries)
        if (sink.samples(e->name) < count) return false;
      return true;
    };
    runFor(p, duration_s, all_counted);
    sink.finish();
    bool reached = true;
    for (const auto* e : entries) {
      spdlog::info("recorded {} samples of {}", sink.samples(e->name), e->name);
      reached = reached && sink.samples(e->name) >= count;
    }
    return reached ? nb::bus::kExitOk : nb::bus::kExitRuntimeError;
  }

 private:
  std::vector<std::string> record_topics;
  std::string out;
  std::string format{"csv"};
  bool record_all{false};
  bool foxglove{false};
  double idle_s{0.0};
  std::uint64_t count{0};
  double duration_s{0.0};
  double flush_s{1.0};
};

/// `navbus recover IN -o OUT`: an MCAP recording cut short (a killed recorder) rewritten whole.
class RecoverCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.add_subcommand(
        "recover",
        "rewrite an MCAP recording that was cut short (a killed recorder, a power cut, a full "
        "disk) with every complete message, its summary and indexes, as the mcap tool's recover "
        "does; a complete file is copied message by message");
    cli_->add_option("in", in, "the MCAP file to read")->required()->check(CLI::ExistingFile);
    cli_->add_option("-o,--out", out, "the recovered MCAP file (created)")->required();
  }
  bool usesBus() const override { return false; }
  int run(bus::Participant::Options&, bus::ShutdownSignal&) override {
    const records::McapRecovery r = records::recoverMcap(in, out);
    if (r.contents.cut) {
      std::printf("%s\n", records::describeCut(in, *r.contents.cut).c_str());
    } else {
      std::printf("%s was closed (complete)\n", in.c_str());
    }
    std::printf("%s: %llu messages on %zu channels in %u chunks, closed with its summary\n",
                out.c_str(), static_cast<unsigned long long>(r.messages_written),
                r.contents.channels.size(), r.contents.chunk_count);
    return nb::bus::kExitOk;
  }

 private:
  std::string in, out;
};

}  // namespace

void addInspectionSubcommands(Subcommands& out) {
  out.push_back(std::make_unique<TopicsCommand>());
  out.push_back(std::make_unique<EchoCommand>());
  out.push_back(std::make_unique<RecordCommand>());
  out.push_back(std::make_unique<RecoverCommand>());
}

}  // namespace navbus::tool::cli
