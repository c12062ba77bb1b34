// MCAP recordings (https://mcap.dev/spec, major version 0), written and read as the published
// specification describes them: the leading magic, a Header, the data section (schemas and
// channels, then chunks of messages, each chunk followed by its message indexes; Data End with
// the data section's CRC-32), the summary section (schemas, channels, statistics, chunk
// indexes, grouped by opcode), the summary offsets, the Footer with the summary's CRC-32, and
// the trailing magic. Chunks are zstd-compressed or stored. What `navbus record --format mcap`
// writes and `navbus replay` reads; Foxglove, PlotJuggler and the mcap CLI read it as well.
//
// Crash safety: the writer puts each chunk on the disk when it closes it (flush(), at least as
// often as its caller asks), so a killed writer leaves a file whose data section is complete up
// to its last chunk; readMcap() reads such a file up to its last complete record and says what
// was lost, and recoverMcap() rewrites it with Data End, summary and indexes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace navbus::records {

struct McapSchema {
  std::uint16_t id{0};
  std::string name;      ///< e.g. the type's scoped name, navbus::ImuIncrement
  std::string encoding;  ///< omgidl, ros2msg, ...
  std::string data;      ///< the schema text
};

struct McapChannel {
  std::uint16_t id{0};
  std::uint16_t schema_id{0};
  std::string topic;
  std::string message_encoding;  ///< cdr for DDS samples
  std::map<std::string, std::string> metadata;
};

struct McapMessage {
  std::uint16_t channel_id{0};
  std::uint32_t sequence{0};
  std::uint64_t log_time_ns{0};      ///< when it was recorded
  std::uint64_t publish_time_ns{0};  ///< when it was published
  std::vector<std::uint8_t> data;
};

enum class McapCompression { kNone, kZstd };

struct McapWriterOptions {
  /// A chunk is closed once its uncompressed records reach this size.
  std::size_t chunk_size_bytes{1u << 20};
  McapCompression compression{McapCompression::kZstd};
  std::string profile;  ///< the Header's profile: empty, or "ros2" for ROS 2 recordings
  std::string library;  ///< the Header's library: who wrote the file
};

/// Writes one MCAP file. Schemas and channels are written to the data section when added (and
/// again in the summary); messages go into chunks. close() (or the destructor) writes the rest.
/// Throws std::runtime_error naming the file and the system's reason (a full disk: "No space
/// left on device") when the file cannot be written; what was flushed before stays readable.
class McapWriter {
 public:
  McapWriter(const std::filesystem::path& file, McapWriterOptions options);
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  /// Returns the new schema's id (1, 2, ...).
  std::uint16_t addSchema(const std::string& name, const std::string& encoding,
                          const std::string& data);
  /// Returns the new channel's id (0, 1, ...).
  std::uint16_t addChannel(std::uint16_t schema_id, const std::string& topic,
                           const std::string& message_encoding,
                           const std::map<std::string, std::string>& metadata = {});
  /// A Metadata record in the data section (indexed in the summary).
  void addMetadata(const std::string& name, const std::map<std::string, std::string>& metadata);
  /// One message of a channel added before; its sequence is the channel's message count.
  void write(std::uint16_t channel_id, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
             const std::vector<std::uint8_t>& data);
  /// Closes the open chunk (with its message indexes) and has the system write the file's bytes
  /// to the disk (fdatasync): what was written survives a crash of this process and of the
  /// machine. Nothing happens when no message came since the last flush.
  void flush();
  /// Closes the open chunk, writes Data End, the summary and the footer. Idempotent.
  void close();

  std::uint64_t messageCount() const { return message_count_; }
  /// Messages written into the open chunk, not yet on the disk.
  std::uint64_t pendingMessages() const { return pending_messages_; }

 private:
  void writeRecord(std::uint8_t opcode, const std::vector<std::uint8_t>& content);
  void writeBytes(const std::vector<std::uint8_t>& bytes);
  void flushChunk();
  void writeSummary();
  [[noreturn]] void failWrite(const char* what) const;

  std::filesystem::path path_;
  int fd_{-1};
  McapWriterOptions options_;
  std::uint64_t offset_{0};  ///< bytes written so far
  /// CRC-32 of the section being written: the data section (from the leading magic up to Data
  /// End), then the summary (up to the footer's CRC field).
  std::uint32_t running_crc_{0};
  bool closed_{false};
  std::vector<McapSchema> schemas_;
  std::vector<McapChannel> channels_;
  std::vector<std::uint32_t> channel_counts_;                ///< messages per channel id
  std::vector<std::vector<std::uint8_t>> chunk_indexes_;     ///< ChunkIndex record contents
  std::vector<std::vector<std::uint8_t>> metadata_indexes_;  ///< MetadataIndex record contents
  std::uint64_t message_count_{0};
  std::uint64_t pending_messages_{0};
  std::uint64_t start_ns_{0}, end_ns_{0};
  std::uint32_t chunk_count_{0};
  // The open chunk: its records, their time span, and each channel's (log time, offset) pairs.
  std::vector<std::uint8_t> chunk_;
  std::uint64_t chunk_start_ns_{0}, chunk_end_ns_{0};
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;
};

struct McapMetadata {
  std::string name;
  std::map<std::string, std::string> entries;
};

/// What a file cut short (a writer killed, a power cut, a full disk) lost: it ends without
/// Data End, summary and trailing magic, often inside a record.
struct McapCut {
  std::uint64_t file_bytes{0};
  std::uint64_t complete_bytes{0};  ///< up to the end of its last complete record
  std::uint64_t lostBytes() const { return file_bytes - complete_bytes; }
  std::string last_record;  ///< the last complete record's kind (Chunk, Message Index, ...)
  std::string lost_record;  ///< the incomplete record's kind, if the cut is inside one
  /// The newest log time of the messages read (none: no message survived).
  std::optional<std::uint64_t> last_log_time_ns;
};

/// Everything in an MCAP file's data section, messages in file order.
struct McapContents {
  std::string profile, library;
  std::map<std::uint16_t, McapSchema> schemas;
  std::map<std::uint16_t, McapChannel> channels;
  std::vector<McapMessage> messages;
  std::vector<McapMetadata> metadata;
  std::uint32_t chunk_count{0};
  std::optional<McapCut> cut;  ///< set when the file was cut short
};

/// Reads a file front to back, checking the leading magic, every record's length, the chunks'
/// and the data section's CRC-32 where present, and that every message's channel and every
/// channel's schema came before it. A file that ends without Data End (cut short) is read up to
/// its last complete record, `cut` saying what was lost. Throws bus::ConfigError naming the
/// file, the byte offset, the record and the field for a malformed file.
McapContents readMcap(const std::filesystem::path& file);

/// One line for a user: the bytes a cut-short file lost and when its last message was logged.
std::string describeCut(const std::filesystem::path& file, const McapCut& cut);

struct McapRecovery {
  McapContents contents;  ///< what was read (its `cut` empty if the file was complete)
  std::uint64_t messages_written{0};
};

/// Rewrites `in` (complete or cut short) into `out` with its schemas, channels, metadata and
/// every message read, chunked and closed (Data End, summary, chunk and message indexes), as
/// the mcap tool's `recover` does. `out` must differ from `in`.
McapRecovery recoverMcap(const std::filesystem::path& in, const std::filesystem::path& out);

/// True if the file starts with the MCAP magic.
bool isMcapFile(const std::filesystem::path& file);

}  // namespace navbus::records
