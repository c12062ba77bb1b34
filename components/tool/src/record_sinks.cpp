#include "navbus/tool/record_sinks.hpp"

#include <stdexcept>

#include "navbus/bus/config.hpp"
#include "navbus/bus/dds_context.hpp"
#include "navbus/foxglove/schemas.hpp"
#include "navbus/records/recording_layout.hpp"
#include "navbus/tool/foxglove_channels.hpp"

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
  const std::filesystem::path path = dir_ / records::recordFileName(e.name);
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
    if (!*f)
      throw std::runtime_error("cannot write " + (dir_ / records::recordFileName(name)).string());
  }
}

void CsvRecordSink::finish() {
  flush();
}

McapRecordSink::McapRecordSink(const std::filesystem::path& file, bool ros2, bool foxglove)
    : ros2_(ros2),
      writer_(file, records::McapWriterOptions{1u << 20, records::McapCompression::kZstd,
                                               ros2 ? "ros2" : "", "navbus record"}) {
  if (!foxglove) return;
  for (const DerivedChannelSchema& d : derivedChannelSchemas(ros2)) {
    const std::uint16_t schema =
        writer_.addSchema(d.schema_name, foxglove::kJsonSchemaEncoding, d.schema);
    derived_channels_.push_back(writer_.addChannel(schema, d.topic, foxglove::kJsonEncoding, {}));
  }
}

void McapRecordSink::open(const TopicEntry& e) {
  const TopicSchema t = topicSchema(e, ros2_);
  auto [it, added] = schema_of_type_.try_emplace(e.type_name, 0);
  if (added) it->second = writer_.addSchema(t.schema_name, t.schema_encoding, t.schema);
  channel_of_topic_[e.name] = writer_.addChannel(it->second, t.channel_topic, kCdr, t.metadata);
}

void McapRecordSink::onSample(const std::string& topic, const SampleTimes& times,
                              const SampleViews& sample) {
  counted(topic);
  writer_.write(channel_of_topic_.at(topic), nonNegative(times.reception_ns),
                nonNegative(times.source_ns), sample.cdr());
  if (derived_channels_.empty()) return;
  if (std::optional<DerivedMessage> m = sample.derived()) {
    writer_.write(derived_channels_.at(static_cast<std::size_t>(m->channel)),
                  nonNegative(times.reception_ns), nonNegative(times.source_ns), m->json);
  }
}

void McapRecordSink::flush() {
  writer_.flush();
}

void McapRecordSink::finish() {
  writer_.close();
}

}  // namespace navbus::tool
