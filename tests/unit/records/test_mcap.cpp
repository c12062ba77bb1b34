// The MCAP writer and reader against the specification (mcap.dev/spec): what is written reads
// back unchanged, stored or zstd-compressed, across chunks; the file's layout (magic, summary,
// summary offsets, footer CRC) is checked by walking it here, independently of the reader; a
// damaged file is refused with the byte offset, record and field; a file cut short reads up to
// its last complete record and is recovered whole. Foxglove's own readers check
// navbus's files in tests/mcap.
#include <gtest/gtest.h>
#include <navbus_idl/IdlSchemas.h>

#include <unistd.h>
#include <zlib.h>
#include <cstring>
#include <fstream>
#include <iterator>

#include "navbus/bus/config.hpp"
#include "navbus/records/mcap.hpp"

using namespace navbus;
using records::McapCompression;

namespace {

/// A file of this process in the temporary directory; each test removes its own.
std::filesystem::path scratch(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         ("navbus-mcap-" + std::to_string(::getpid()) + "-" + name);
}

std::vector<std::uint8_t> bytesOf(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void writeBytes(const std::filesystem::path& file, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

std::uint64_t le(const std::vector<std::uint8_t>& b, std::size_t at, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v |= std::uint64_t{b[at + i]} << (8 * i);
  return v;
}

struct Written {
  std::vector<records::McapMessage> messages;
};

/// Two schemas, three channels, `n` messages of varied sizes with small chunks.
Written writeSample(const std::filesystem::path& file, McapCompression compression, int n) {
  records::McapWriter w(file, {4096, compression, "", "navbus test"});
  const auto s1 = w.addSchema("navbus::ImuIncrement", "omgidl", "module navbus { };");
  const auto s2 = w.addSchema("navbus::GnssFix", "omgidl", "module navbus { };");
  const auto c0 = w.addChannel(s1, "navbus/imu/increment", "cdr", {{"dds_type", "a"}});
  const auto c1 = w.addChannel(s2, "navbus/gnss/fix", "cdr");
  const auto c2 = w.addChannel(s2, "navbus/gnss/fix2", "cdr");
  w.addMetadata("navbus", {{"version", "test"}});
  Written out;
  std::uint32_t seq[3] = {0, 0, 0};
  for (int i = 0; i < n; ++i) {
    const std::uint16_t channel = i % 7 == 0 ? c1 : (i % 11 == 0 ? c2 : c0);
    records::McapMessage m{
        channel, seq[channel]++, 1'000'000'000ull + 1000ull * i, 999'000'000ull + 1000ull * i, {}};
    for (int k = 0; k < 4 + i % 60; ++k) m.data.push_back(static_cast<std::uint8_t>(i * 31 + k));
    w.write(m.channel_id, m.log_time_ns, m.publish_time_ns, m.data);
    out.messages.push_back(m);
  }
  w.close();
  return out;
}

}  // namespace

class McapRoundTrip : public ::testing::TestWithParam<McapCompression> {};

TEST_P(McapRoundTrip, WhatIsWrittenReadsBackUnchanged) {
  const auto file = scratch("round_trip.mcap");
  const Written written = writeSample(file, GetParam(), 3000);
  const records::McapContents read = records::readMcap(file);
  EXPECT_EQ(read.library, "navbus test");
  ASSERT_EQ(read.schemas.size(), 2u);
  EXPECT_EQ(read.schemas.at(1).name, "navbus::ImuIncrement");
  EXPECT_EQ(read.schemas.at(2).encoding, "omgidl");
  ASSERT_EQ(read.channels.size(), 3u);
  EXPECT_EQ(read.channels.at(0).topic, "navbus/imu/increment");
  EXPECT_EQ(read.channels.at(0).metadata.at("dds_type"), "a");
  EXPECT_EQ(read.channels.at(2).schema_id, 2);
  EXPECT_GT(read.chunk_count, 10u);  // 4 KiB chunks
  ASSERT_EQ(read.messages.size(), written.messages.size());
  for (std::size_t i = 0; i < read.messages.size(); ++i) {
    const auto& a = read.messages[i];
    const auto& b = written.messages[i];
    ASSERT_EQ(a.channel_id, b.channel_id) << i;
    ASSERT_EQ(a.sequence, b.sequence) << i;
    ASSERT_EQ(a.log_time_ns, b.log_time_ns) << i;
    ASSERT_EQ(a.publish_time_ns, b.publish_time_ns) << i;
    ASSERT_EQ(a.data, b.data) << i;
  }
  std::filesystem::remove(file);
}

INSTANTIATE_TEST_SUITE_P(StoredAndZstd, McapRoundTrip,
                         ::testing::Values(McapCompression::kNone, McapCompression::kZstd));

// The layout a reader that seeks uses, walked from the footer: summary groups by opcode, the
// Summary Offset records pointing at them, the summary CRC, chunk indexes pointing at chunks.
TEST(Mcap, TheSummaryAndItsOffsetsDescribeTheFile) {
  const auto file = scratch("layout.mcap");
  writeSample(file, McapCompression::kZstd, 500);
  const auto b = bytesOf(file);
  ASSERT_GT(b.size(), 16u + 29u);
  const std::size_t footer = b.size() - 8 - 29;  // opcode, length 20, 8 + 8 + 4
  ASSERT_EQ(b[footer], 0x02);
  ASSERT_EQ(le(b, footer + 1, 8), 20u);
  const std::size_t summary_start = le(b, footer + 9, 8);
  const std::size_t offsets_start = le(b, footer + 17, 8);
  const auto crc = static_cast<std::uint32_t>(le(b, footer + 25, 4));
  EXPECT_EQ(crc, static_cast<std::uint32_t>(::crc32(
                     0, b.data() + summary_start, static_cast<uInt>(footer + 25 - summary_start))));
  // The record before the summary is Data End.
  ASSERT_EQ(b[summary_start - 13], 0x0F);
  // Summary records, grouped by opcode.
  std::vector<std::uint8_t> opcodes;
  std::vector<std::size_t> chunk_offsets;
  for (std::size_t at = summary_start; at < offsets_start;) {
    const std::uint8_t op = b[at];
    const std::size_t n = le(b, at + 1, 8);
    if (opcodes.empty() || opcodes.back() != op) opcodes.push_back(op);
    if (op == 0x08) chunk_offsets.push_back(le(b, at + 9 + 16, 8));
    at += 9 + n;
  }
  EXPECT_EQ(opcodes, (std::vector<std::uint8_t>{0x03, 0x04, 0x0B, 0x08, 0x0D}));
  ASSERT_FALSE(chunk_offsets.empty());
  for (std::size_t at : chunk_offsets) EXPECT_EQ(b[at], 0x06) << "chunk index points at " << at;
  // One Summary Offset per group, each at its group's first record.
  std::size_t groups = 0;
  for (std::size_t at = offsets_start; at < footer; ++groups) {
    ASSERT_EQ(b[at], 0x0E);
    const std::uint8_t group_op = b[at + 9];
    EXPECT_EQ(b[le(b, at + 10, 8)], group_op);
    at += 9 + le(b, at + 1, 8);
  }
  EXPECT_EQ(groups, 5u);
  std::filesystem::remove(file);
}

TEST(Mcap, ADamagedFileIsRefusedNamingWhere) {
  const auto file = scratch("damaged.mcap");
  writeSample(file, McapCompression::kNone, 200);
  const auto good = bytesOf(file);
  const auto refusal = [&](const std::vector<std::uint8_t>& bytes) {
    writeBytes(file, bytes);
    try {
      records::readMcap(file);
    } catch (const bus::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  // One byte of a stored chunk's records changed.
  auto flipped = good;
  const std::size_t chunk = [&] {
    for (std::size_t at = 8;;) {
      if (good[at] == 0x06) return at;
      at += 9 + le(good, at + 1, 8);
    }
  }();
  flipped[chunk + 9 + 60] ^= 0x40;
  const std::string crc = refusal(flipped);
  EXPECT_NE(crc.find("byte " + std::to_string(chunk) + ": Chunk field 'uncompressed_crc'"),
            std::string::npos)
      << crc;
  // Not an MCAP file at all.
  EXPECT_NE(
      refusal({'t', 'i', 'm', 'e', ',', 'x', '\n', '1', ',', '2', '\n', '3', '4', '5', '6', '7'})
          .find("MCAP magic"),
      std::string::npos);
  // A record whose length runs past the file.
  auto long_record = good;
  long_record[8 + 1 + 7] = 0x7F;  // the Header's length, high byte
  EXPECT_NE(refusal(long_record).find("record length"), std::string::npos);
  std::filesystem::remove(file);
}

/// Messages equal in every field (the writer numbers sequences per channel as written).
void expectSameMessages(const std::vector<records::McapMessage>& read,
                        const std::vector<records::McapMessage>& written, std::size_t n) {
  ASSERT_EQ(read.size(), n);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(read[i].channel_id, written[i].channel_id) << i;
    EXPECT_EQ(read[i].sequence, written[i].sequence) << i;
    EXPECT_EQ(read[i].log_time_ns, written[i].log_time_ns) << i;
    EXPECT_EQ(read[i].publish_time_ns, written[i].publish_time_ns) << i;
    EXPECT_EQ(read[i].data, written[i].data) << i;
  }
}

// A recorder killed after it flushed: the file as the kill leaves it (the writer still open,
// 40 messages in its open chunk) reads up to the flush, whatever byte the cut falls on.
TEST(McapCut, AKilledWritersFileReadsUpToItsLastCompleteRecord) {
  const auto file = scratch("killed.mcap");
  const auto copy = scratch("killed-copy.mcap");
  std::vector<std::uint8_t> at_kill;
  Written w;
  {
    records::McapWriter writer(file, {4096, McapCompression::kZstd, "", "navbus test"});
    const auto ch = writer.addChannel(writer.addSchema("s", "omgidl", "module m { };"), "t", "cdr");
    writer.addMetadata("navbus", {{"version", "test"}});
    for (std::uint32_t i = 0; i < 100; ++i) {
      if (i == 60) {
        writer.flush();
        EXPECT_EQ(writer.pendingMessages(), 0u);
      }
      w.messages.push_back({ch, i, 5'000'000'000ull + 10'000'000ull * i, 7ull * i,
                            std::vector<std::uint8_t>(20 + i % 9, static_cast<std::uint8_t>(i))});
      writer.write(ch, w.messages.back().log_time_ns, w.messages.back().publish_time_ns,
                   w.messages.back().data);
    }
    EXPECT_EQ(writer.pendingMessages(), 40u);
    at_kill = bytesOf(file);
  }
  writeBytes(copy, at_kill);
  const records::McapContents c = records::readMcap(copy);
  expectSameMessages(c.messages, w.messages, 60);
  ASSERT_TRUE(c.cut.has_value());
  EXPECT_EQ(c.cut->file_bytes, at_kill.size());
  EXPECT_EQ(c.cut->lostBytes(), 0u);  // the flush wrote the chunk and its indexes whole
  EXPECT_EQ(c.cut->last_record, "Message Index");
  EXPECT_EQ(c.cut->last_log_time_ns, w.messages[59].log_time_ns);
  ASSERT_EQ(c.metadata.size(), 1u);
  EXPECT_EQ(c.metadata[0].entries.at("version"), "test");
  const std::string said = records::describeCut(copy, *c.cut);
  EXPECT_NE(said.find("cut short"), std::string::npos) << said;
  EXPECT_NE(said.find("1970-01-01 00:00:05 UTC"), std::string::npos) << said;

  // Every cut of the closed file inside its data section keeps the messages of the chunks
  // before the cut and says how many bytes were lost.
  const auto closed = bytesOf(file);
  std::size_t first_chunk_end = 0, kept_before = 0;
  for (std::size_t cut = 8; cut + 8 < closed.size(); cut += 7) {
    writeBytes(copy, {closed.begin(), closed.begin() + static_cast<std::ptrdiff_t>(cut)});
    records::McapContents part;
    ASSERT_NO_THROW(part = records::readMcap(copy)) << "cut at byte " << cut;
    if (!part.cut) break;  // past Data End: the data section is whole
    EXPECT_EQ(part.cut->complete_bytes + part.cut->lostBytes(), cut);
    EXPECT_GE(part.messages.size(), kept_before) << "cut at byte " << cut;
    kept_before = part.messages.size();
    if (kept_before > 0 && first_chunk_end == 0) first_chunk_end = cut;
    expectSameMessages(part.messages, w.messages, part.messages.size());
  }
  EXPECT_EQ(kept_before, 100u);
  EXPECT_GT(first_chunk_end, 0u);

  // A tail the file system allocated but never wrote (a power cut) reads as the cut it is.
  auto zero_tail = at_kill;
  zero_tail.resize(at_kill.size() + 4096, 0);
  writeBytes(copy, zero_tail);
  const records::McapContents z = records::readMcap(copy);
  expectSameMessages(z.messages, w.messages, 60);
  ASSERT_TRUE(z.cut.has_value());
  EXPECT_EQ(z.cut->lostBytes(), 4096u);
  EXPECT_EQ(z.cut->lost_record, "zero bytes, never written");
  std::filesystem::remove(file);
  std::filesystem::remove(copy);
}

// `navbus recover`: the cut file rewritten whole reads as a closed file with the same messages,
// metadata, and a summary whose statistics count them.
TEST(McapCut, ARecoveredFileIsClosedWithEveryCompleteMessage) {
  const auto file = scratch("recover-in.mcap");
  const auto out = scratch("recover-out.mcap");
  const Written w = writeSample(file, McapCompression::kZstd, 300);
  auto bytes = bytesOf(file);
  bytes.resize(bytes.size() * 2 / 3);
  writeBytes(file, bytes);
  const records::McapRecovery r = records::recoverMcap(file, out);
  ASSERT_TRUE(r.contents.cut.has_value());
  const std::size_t kept = r.contents.messages.size();
  EXPECT_GT(kept, 0u);
  EXPECT_LT(kept, 300u);
  EXPECT_EQ(r.messages_written, kept);
  const records::McapContents again = records::readMcap(out);
  EXPECT_FALSE(again.cut.has_value());
  expectSameMessages(again.messages, w.messages, kept);
  EXPECT_EQ(again.channels.size(), 3u);
  EXPECT_EQ(again.schemas.size(), 2u);
  ASSERT_EQ(again.metadata.size(), 1u);
  EXPECT_EQ(again.library, "navbus test");
  // The summary's Statistics record counts the messages (the footer's summary start, then the
  // Statistics record after the schemas and channels).
  const auto recovered = bytesOf(out);
  const std::size_t footer = recovered.size() - 8 - 29;
  ASSERT_EQ(recovered[footer], 0x02);
  std::size_t at = le(recovered, footer + 9, 8);
  while (recovered[at] != 0x0B) at += 9 + le(recovered, at + 1, 8);
  EXPECT_EQ(le(recovered, at + 9, 8), kept);
  // The output must not be the input.
  EXPECT_THROW(records::recoverMcap(out, out), bus::ConfigError);
  std::filesystem::remove(file);
  std::filesystem::remove(out);
}

// The schemas Foxglove's parsers need: one self-contained IDL text (no #include, no
// preprocessor line, no hexadecimal literal) and a ROS 2 message definition with its
// dependencies.
TEST(McapSchemas, EveryTopicTypeHasSelfContainedSchemas) {
  for (const char* type :
       {"navbus::ImuIncrement", "navbus::ImuIncrementBlock", "navbus::ImuRawBlock",
        "navbus::GnssObservationEpoch", "navbus::GnssFix", "navbus::StarTrackerAttitude",
        "navbus::GnssObservationEpochBlock", "navbus::GnssFixBlock",
        "navbus::StarTrackerAttitudeBlock", "navbus::NavigationSolution",
        "navbus::FilterDiagnostics", "navbus::FaultDecision", "navbus::FilterCommand",
        "navbus::FilterCommandOutcome", "navbus::FaultMonitorProgress", "navbus::Health"}) {
    const auto* s = idl_schemas::find(type);
    ASSERT_NE(s, nullptr) << type;
    const std::string idl(s->omgidl);
    EXPECT_EQ(idl.find('#'), std::string::npos) << type;
    EXPECT_EQ(idl.find("0x"), std::string::npos) << type;
    EXPECT_EQ(idl.find("//"), std::string::npos) << type;
    const std::string bare = std::string(type).substr(8);
    EXPECT_NE(idl.find("struct " + bare + " {"), std::string::npos) << type;
    EXPECT_EQ(s->ros2_name, "navbus/msg/" + bare);
  }
  const std::string block(idl_schemas::find("navbus::ImuIncrementBlock")->ros2msg);
  EXPECT_EQ(block.rfind("uint32 sensor_id\nuint64 seq\nnavbus/ImuIncrement[<=128] increments\n", 0),
            0u)
      << block;
  EXPECT_NE(block.find("\n" + std::string(80, '=') + "\nMSG: navbus/ImuIncrement\n"),
            std::string::npos);
  const std::string solution(idl_schemas::find("navbus::NavigationSolution")->ros2msg);
  EXPECT_NE(solution.find("uint32 FAULT_NO_FAULT_MONITOR=256\n"), std::string::npos);
  EXPECT_NE(solution.find("uint32 MODE_INERTIAL_LOST=8\n"), std::string::npos);
  EXPECT_NE(solution.find("float64[4] q_b_to_n\n"), std::string::npos);
  EXPECT_EQ(idl_schemas::find("navbus::NoSuchType"), nullptr);
}
