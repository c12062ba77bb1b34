// What `navbus record` writes: one CSV file per topic (the message's columns, then its DDS source
// and reception time stamps), or one MCAP file with a channel per topic (the sample's CDR bytes,
// its reception time as the log time and its source time as the publish time, each topic's
// type as a self-contained OMG IDL schema, or as a ROS 2 message definition under ROS 2 naming).
// Both count the samples of each topic and when the last one came.
#pragma once

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "navbus/records/mcap.hpp"
#include "navbus/tool/topic_registry.hpp"

namespace navbus::tool {

class RecordSink : public SampleSink {
 public:
  /// Prepares the topic's file or channel (before it is subscribed to).
  virtual void open(const TopicEntry& topic) = 0;
  /// Puts what was recorded since the last flush on the disk (a crash then loses nothing
  /// before it).
  virtual void flush() = 0;
  /// Writes what is buffered and closes the recording.
  virtual void finish() = 0;
  std::uint64_t samples(const std::string& topic) const;
  /// Seconds since the last sample of any topic; negative before the first.
  double idleSeconds() const;

 protected:
  void counted(const std::string& topic);

 private:
  std::map<std::string, std::uint64_t> samples_;
  std::optional<std::chrono::steady_clock::time_point> last_sample_;
};

/// One CSV file per topic in a directory (records::recordFileName()).
class CsvRecordSink final : public RecordSink {
 public:
  explicit CsvRecordSink(std::filesystem::path dir);
  void open(const TopicEntry& topic) override;
  void onSample(const std::string& topic, const SampleTimes& times,
                const SampleViews& sample) override;
  /// Hands every file's buffered rows to the system (not synced: a crash of the recorder loses
  /// nothing flushed, a crash of the machine may).
  void flush() override;
  void finish() override;

 private:
  std::filesystem::path dir_;
  std::map<std::string, std::unique_ptr<std::ofstream>> files_;
};

/// One MCAP file; `ros2`: the bus runs under ROS 2 naming, so the channels carry the ROS 2
/// topic names ("/navbus/imu/increment") and ros2msg schemas ("navbus/msg/ImuIncrement").
/// `foxglove`: the channels in Foxglove's schemas derived from the recorded topics are written
/// too (foxglove_channels.hpp; JSON messages, with the sample's times).
class McapRecordSink final : public RecordSink {
 public:
  McapRecordSink(const std::filesystem::path& file, bool ros2, bool foxglove);
  void open(const TopicEntry& topic) override;
  void onSample(const std::string& topic, const SampleTimes& times,
                const SampleViews& sample) override;
  /// Closes the open chunk and syncs the file (records::McapWriter::flush).
  void flush() override;
  void finish() override;

 private:
  bool ros2_;
  records::McapWriter writer_;
  std::map<std::string, std::uint16_t> schema_of_type_, channel_of_topic_;
  /// The derived channels' ids (foxglove), in DerivedChannel order.
  std::vector<std::uint16_t> derived_channels_;
};

}  // namespace navbus::tool
