// What a cut-short MCAP file lost, said for a user, and the file rewritten whole.
#include <chrono>

#include <fmt/chrono.h>
#include <fmt/format.h>

#include "navbus/bus/config.hpp"
#include "navbus/records/mcap.hpp"

namespace navbus::records {

namespace {

/// A log time (nanoseconds since the Unix epoch, the recorder's clock) as UTC text.
std::string utcText(std::uint64_t ns) {
  using Ms = std::chrono::milliseconds;
  const std::chrono::time_point<std::chrono::system_clock, Ms> t{
      Ms(static_cast<std::int64_t>(ns / 1'000'000))};
  return fmt::format("{:%Y-%m-%d %H:%M:%S} UTC", t);
}

}  // namespace

std::string describeCut(const std::filesystem::path& file, const McapCut& cut) {
  std::string text = fmt::format(
      "{} was cut short (not closed: no Data End, summary or trailing magic): {} of its {} bytes "
      "are complete records, the last a {}; ",
      file.string(), cut.complete_bytes, cut.file_bytes,
      cut.last_record.empty() ? "none" : cut.last_record);
  text += cut.lostBytes() == 0
              ? std::string("no bytes lost after it; ")
              : fmt::format("the last {} bytes ({}) are lost; ", cut.lostBytes(),
                            cut.lost_record.empty() ? "an incomplete record" : cut.lost_record);
  text += cut.last_log_time_ns ? fmt::format("the last complete message was logged at {} ({} ns)",
                                             utcText(*cut.last_log_time_ns), *cut.last_log_time_ns)
                               : std::string("no complete message");
  return text;
}

McapRecovery recoverMcap(const std::filesystem::path& in, const std::filesystem::path& out) {
  std::error_code ec;
  if (std::filesystem::exists(out) && std::filesystem::equivalent(in, out, ec)) {
    throw bus::ConfigError("recover: the output " + out.string() +
                           " is the input; write the recovered file beside it");
  }
  McapRecovery r;
  r.contents = readMcap(in);
  const McapContents& c = r.contents;
  McapWriter writer(out, McapWriterOptions{1u << 20, McapCompression::kZstd, c.profile,
                                           c.library.empty() ? "navbus recover" : c.library});
  // The writer numbers schemas from 1 and channels from 0 in the order added; the file's own
  // ids may differ (or have gaps), so messages are mapped through the new ids.
  std::map<std::uint16_t, std::uint16_t> schema_id, channel_id;
  for (const auto& [id, s] : c.schemas)
    schema_id[id] = writer.addSchema(s.name, s.encoding, s.data);
  for (const auto& [id, ch] : c.channels) {
    if (ch.schema_id == 0) {
      throw bus::ConfigError(in.string() + ": channel '" + ch.topic +
                             "' has no schema (schema id 0): navbus recover keeps schemas");
    }
    channel_id[id] =
        writer.addChannel(schema_id.at(ch.schema_id), ch.topic, ch.message_encoding, ch.metadata);
  }
  for (const McapMetadata& m : c.metadata) writer.addMetadata(m.name, m.entries);
  for (const McapMessage& m : c.messages) {
    writer.write(channel_id.at(m.channel_id), m.log_time_ns, m.publish_time_ns, m.data);
  }
  writer.close();
  r.messages_written = writer.messageCount();
  return r;
}

}  // namespace navbus::records
