#include "navbus/tool/record_sinks.hpp"

#include <navbus_idl/IdlSchemas.h>

#include <stdexcept>

#include "navbus/bus/config.hpp"
#include "navbus/bus/dds_context.hpp"

namespace navbus::tool {

namespace {
constexpr const char* kCdr = "cdr";  // MCAP's message encoding of (X)CDR samples

std::uint64_t nonNegative(std::int64_t ns) {
  return ns < 0 ? 0 : static_cast<std::uint64_t>(ns);
}
}  // namespace

std::uint64_t RecordSink::samples(const std::string& topic) const {
  const auto it = samples_.find(topic);
  return it == samples_.end() ? 0 : it->second;
}

double RecordSink::idleSeconds() const {
  if (!last_sample_) return -1.0;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - *last_sample_).count();
}

void RecordSink::counted(const std::string& topic) {
  ++samples_[topic];
  last_sample_ = std::chrono::steady_clock::now();
}

CsvRecordSink::CsvRecordSink(std::filesystem::path dir) : dir_(std::move(dir)) {
  std::filesystem::create_directories(dir_);
}

void CsvRecordSink::open(const TopicEntry& e) {
  const std::filesystem::path path = dir_ / recordFileName(e.name);
  auto file = std::make_unique<std::ofstream>(path);
  if (!*file) throw std::runtime_error("cannot write " + path.string());
  *file << e.csv_header << ",source_timestamp_ns,reception_timestamp_ns\n";
  files_[e.name] = std::move(file);
}

void CsvRecordSink::onSample(const std::string& topic, const SampleTimes& times,
                             const SampleViews& sample) {
  auto& file = *files_.at(topic);
  counted(topic);
  for (const auto& r : sample.csv_rows()) {
    file << r << ',' << times.source_ns << ',' << times.reception_ns << '\n';
  }
}

void CsvRecordSink::flush() {
  for (auto& [name, f] : files_) {
    f->flush();
    if (!*f) throw std::runtime_error("cannot write " + (dir_ / recordFileName(name)).string());
  }
}

void CsvRecordSink::finish() {
  flush();
}

McapRecordSink::McapRecordSink(const std::filesystem::path& file, bool ros2)
    : ros2_(ros2),
      writer_(file, records::McapWriterOptions{1u << 20, records::McapCompression::kZstd,
                                               ros2 ? "ros2" : "", "navbus record"}) {}

void McapRecordSink::open(const TopicEntry& e) {
  const idl_schemas::TypeSchema* schema = idl_schemas::find(e.type_name);
  if (schema == nullptr) {
    throw bus::ConfigError("record --format mcap: no schema for type '" + e.type_name + "' of " +
                           e.name);
  }
  auto [it, added] = schema_of_type_.try_emplace(e.type_name, 0);
  if (added) {
    it->second = ros2_ ? writer_.addSchema(std::string(schema->ros2_name), "ros2msg",
                                           std::string(schema->ros2msg))
                       : writer_.addSchema(std::string(schema->type_name), "omgidl",
                                           std::string(schema->omgidl));
  }
  // The DDS names beside the channel's own, for tools that go back to the bus.
  const std::map<std::string, std::string> metadata{
      {"dds_topic", ros2_ ? bus::ros2TopicName(e.name) : e.name},
      {"dds_type", ros2_ ? bus::ros2TypeName(e.type_name) : e.type_name},
      {"reader_profile", e.reader_profile}};
  channel_of_topic_[e.name] =
      writer_.addChannel(it->second, ros2_ ? "/" + e.name : e.name, kCdr, metadata);
}

void McapRecordSink::onSample(const std::string& topic, const SampleTimes& times,
                              const SampleViews& sample) {
  counted(topic);
  writer_.write(channel_of_topic_.at(topic), nonNegative(times.reception_ns),
                nonNegative(times.source_ns), sample.cdr());
}

void McapRecordSink::flush() {
  writer_.flush();
}

void McapRecordSink::finish() {
  writer_.close();
}

}  // namespace navbus::tool
