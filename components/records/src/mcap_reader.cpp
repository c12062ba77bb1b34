#include <cstring>
#include <fstream>
#include <iterator>

#include <zstd.h>

#include "mcap_bytes.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/records/mcap.hpp"

namespace navbus::records {

namespace {

/// One file's bytes and what is known of it, for the error messages.
class McapParser {
 public:
  McapParser(std::string file, std::vector<std::uint8_t> bytes)
      : file_(std::move(file)), bytes_(std::move(bytes)) {}

  McapContents parse() {
    const std::size_t magic = sizeof(mcap::kMagic);
    if (bytes_.size() < magic || std::memcmp(bytes_.data(), mcap::kMagic, magic) != 0) {
      fail(0, "file", "does not start with the MCAP magic (0x89 MCAP0 \\r\\n)");
    }
    // A closed file ends with the magic, and its records end before it; a file cut short ends
    // anywhere, and its last complete record marks what can be read.
    const bool closed =
        bytes_.size() >= 2 * magic &&
        std::memcmp(bytes_.data() + bytes_.size() - magic, mcap::kMagic, magic) == 0;
    const std::size_t end = closed ? bytes_.size() - magic : bytes_.size();
    std::size_t at = magic;
    std::uint8_t last_opcode = 0;
    bool header = false;
    for (;;) {
      if (end - at < 9) {
        if (closed) fail(at, "file", "ends before the Data End record");
        return cutAt(at, last_opcode, at == end ? "" : "record's opcode and length");
      }
      if (bytes_[at] == 0) {  // opcode 0 is reserved: a tail the system allocated, never written
        if (closed) fail(at, "record opcode", "0 is reserved");
        return cutAt(at, last_opcode, "zero bytes, never written");
      }
      const std::uint8_t opcode = bytes_[at];
      std::uint64_t length = 0;
      for (int i = 0; i < 8; ++i) length |= std::uint64_t{bytes_[at + 1 + i]} << (8 * i);
      if (length > end - at - 9) {
        if (closed) {
          fail(at, "record length", std::to_string(length) + " bytes run past the file's end");
        }
        return cutAt(at, last_opcode, mcap::recordName(opcode));
      }
      const std::uint8_t* content = bytes_.data() + at + 9;
      if (!header && opcode != mcap::kHeader) fail(at, "Header", "is not the first record");
      if (opcode == mcap::kHeader) {
        header = true;
        readHeader(at, content, length);
      } else if (opcode == mcap::kDataEnd) {
        checkDataEnd(at, content, length);
        return std::move(contents_);
      } else {
        dataRecord(at, opcode, content, length, false);
      }
      at += 9 + static_cast<std::size_t>(length);
      last_opcode = opcode;
    }
  }

 private:
  [[noreturn]] void fail(std::uint64_t offset, const std::string& field,
                         const std::string& what) const {
    throw bus::ConfigError(file_ + ": byte " + std::to_string(offset) + ": " + field + " " + what);
  }
  mcap::ByteReader reader(std::uint64_t offset, const char* record, const std::uint8_t* content,
                          std::uint64_t length) const {
    return mcap::ByteReader(content, static_cast<std::size_t>(length),
                            [this, offset, record](const char* field) {
                              fail(offset, std::string(record) + " field '" + field + "'",
                                   "runs past the record's end");
                            });
  }

  /// The file ends at byte `at` without Data End; `lost` says what the bytes after it are ("":
  /// none).
  McapContents cutAt(std::uint64_t at, std::uint8_t last, std::string lost) {
    McapCut cut;
    cut.file_bytes = bytes_.size();
    cut.complete_bytes = at;
    cut.last_record = mcap::recordName(last);
    cut.lost_record = std::move(lost);
    for (const McapMessage& m : contents_.messages) {
      cut.last_log_time_ns = std::max(cut.last_log_time_ns.value_or(0), m.log_time_ns);
    }
    contents_.cut = std::move(cut);
    return std::move(contents_);
  }

  void readHeader(std::uint64_t at, const std::uint8_t* content, std::uint64_t length) {
    auto r = reader(at, "Header", content, length);
    contents_.profile = r.str("profile");
    contents_.library = r.str("library");
  }

  void checkDataEnd(std::uint64_t at, const std::uint8_t* content, std::uint64_t length) {
    auto r = reader(at, "Data End", content, length);
    const std::uint32_t crc = r.u32("data_section_crc");
    const auto actual = mcap::crc32Of(0, bytes_.data(), static_cast<std::size_t>(at));
    if (crc != 0 && crc != actual) {
      fail(at, "Data End field 'data_section_crc'",
           std::to_string(crc) + " differs from the data's CRC-32 " + std::to_string(actual));
    }
  }

  /// A record of the data section, or of a chunk (`in_chunk`: offsets within the chunk).
  void dataRecord(std::uint64_t at, std::uint8_t opcode, const std::uint8_t* content,
                  std::uint64_t length, bool in_chunk) {
    switch (opcode) {
      case mcap::kSchema: {
        auto r = reader(at, "Schema", content, length);
        McapSchema s;
        s.id = r.u16("id");
        s.name = r.str("name");
        s.encoding = r.str("encoding");
        s.data = r.str("data");
        if (s.id != 0) contents_.schemas[s.id] = std::move(s);  // id 0: to be ignored (spec)
        break;
      }
      case mcap::kChannel: {
        auto r = reader(at, "Channel", content, length);
        McapChannel c;
        c.id = r.u16("id");
        c.schema_id = r.u16("schema_id");
        c.topic = r.str("topic");
        c.message_encoding = r.str("message_encoding");
        c.metadata = r.stringMap("metadata");
        if (c.schema_id != 0 && contents_.schemas.count(c.schema_id) == 0) {
          fail(
              at, "Channel field 'schema_id'",
              std::to_string(c.schema_id) + " (topic '" + c.topic + "') names no schema before it");
        }
        contents_.channels[c.id] = std::move(c);
        break;
      }
      case mcap::kMessage: {
        auto r = reader(at, "Message", content, length);
        McapMessage m;
        m.channel_id = r.u16("channel_id");
        m.sequence = r.u32("sequence");
        m.log_time_ns = r.u64("log_time");
        m.publish_time_ns = r.u64("publish_time");
        const std::size_t n = r.remaining();
        const std::uint8_t* data = r.bytes("data", n);
        m.data.assign(data, data + n);
        if (contents_.channels.count(m.channel_id) == 0) {
          fail(at, "Message field 'channel_id'",
               std::to_string(m.channel_id) + " names no channel before it");
        }
        contents_.messages.push_back(std::move(m));
        break;
      }
      case mcap::kMetadata: {
        auto r = reader(at, "Metadata", content, length);
        McapMetadata m;
        m.name = r.str("name");
        m.entries = r.stringMap("metadata");
        contents_.metadata.push_back(std::move(m));
        break;
      }
      case mcap::kChunk:
        if (in_chunk) fail(at, "Chunk", "inside a chunk");
        readChunk(at, content, length);
        break;
      default:
        // Message Index, Attachment, and records this reader does not know (the spec
        // lets files carry private records and readers ignore them).
        break;
    }
  }

  void readChunk(std::uint64_t at, const std::uint8_t* content, std::uint64_t length) {
    auto r = reader(at, "Chunk", content, length);
    r.u64("message_start_time");
    r.u64("message_end_time");
    const std::uint64_t size = r.u64("uncompressed_size");
    const std::uint32_t crc = r.u32("uncompressed_crc");
    const std::string compression = r.str("compression");
    const std::uint64_t stored_size = r.u64("records");
    const std::uint8_t* stored = r.bytes("records", stored_size);
    std::vector<std::uint8_t> records;
    if (compression.empty()) {
      if (stored_size != size) {
        fail(at, "Chunk field 'uncompressed_size'",
             std::to_string(size) + " differs from the stored size " + std::to_string(stored_size));
      }
      records.assign(stored, stored + stored_size);
    } else if (compression == "zstd") {
      records.resize(static_cast<std::size_t>(size));
      const std::size_t n = ZSTD_decompress(records.data(), records.size(), stored, stored_size);
      if (ZSTD_isError(n) || n != size) {
        fail(at, "Chunk field 'records'",
             std::string("does not decompress to uncompressed_size bytes: ") +
                 (ZSTD_isError(n) ? ZSTD_getErrorName(n) : std::to_string(n) + " bytes"));
      }
    } else {
      fail(at, "Chunk field 'compression'", "'" + compression + "' is not supported (zstd, none)");
    }
    const auto actual = mcap::crc32Of(0, records.data(), records.size());
    if (crc != 0 && crc != actual) {
      fail(at, "Chunk field 'uncompressed_crc'",
           std::to_string(crc) + " differs from the records' CRC-32 " + std::to_string(actual));
    }
    ++contents_.chunk_count;
    for (std::size_t pos = 0; pos < records.size();) {
      if (records.size() - pos < 9) fail(at, "Chunk field 'records'", "ends inside a record");
      std::uint64_t n = 0;
      for (int i = 0; i < 8; ++i) n |= std::uint64_t{records[pos + 1 + i]} << (8 * i);
      if (n > records.size() - pos - 9) {
        fail(at, "Chunk field 'records'",
             "holds a record of " + std::to_string(n) + " bytes past the chunk's end");
      }
      dataRecord(at, records[pos], records.data() + pos + 9, n, true);
      pos += 9 + static_cast<std::size_t>(n);
    }
  }

  std::string file_;
  std::vector<std::uint8_t> bytes_;
  McapContents contents_;
};

std::vector<std::uint8_t> readAll(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw bus::ConfigError(file.string() + ": cannot be read");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

McapContents readMcap(const std::filesystem::path& file) {
  return McapParser(file.string(), readAll(file)).parse();
}

bool isMcapFile(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  char head[sizeof(mcap::kMagic)] = {};
  in.read(head, sizeof(head));
  return in && std::memcmp(head, mcap::kMagic, sizeof(head)) == 0;
}

}  // namespace navbus::records
