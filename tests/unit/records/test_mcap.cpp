// The MCAP writer and reader against the specification (mcap.dev/spec): what is written reads
// back unchanged, stored or zstd-compressed, across chunks; the file's layout (magic, summary,
// summary offsets, footer CRC) is checked by walking it here, independently of the reader; a
// damaged file is refused with the byte offset, record and field. Foxglove's own readers check
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
  // Cut short: a recorder killed before it closed the file.
  EXPECT_NE(refusal({good.begin(), good.begin() + good.size() / 2}).find("cut short"),
            std::string::npos);
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

// The schemas Foxglove's parsers need: one self-contained IDL text (no #include, no
// preprocessor line, no hexadecimal literal) and a ROS 2 message definition with its
// dependencies.
TEST(McapSchemas, EveryTopicTypeHasSelfContainedSchemas) {
  for (const char* type :
       {"navbus::ImuIncrement", "navbus::ImuIncrementBlock", "navbus::ImuRawBlock",
        "navbus::GnssObservationEpoch", "navbus::GnssFix", "navbus::StarTrackerAttitude",
        "navbus::NavigationSolution", "navbus::FilterDiagnostics", "navbus::FaultDecision",
        "navbus::FilterCommand", "navbus::FilterCommandOutcome", "navbus::FaultMonitorProgress",
        "navbus::Health"}) {
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
  EXPECT_EQ(block.rfind("uint32 sensor_id\nuint64 seq\nnavbus/ImuIncrement[<=64] increments\n", 0),
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
