#include <cerrno>
#include <cstring>
#include <stdexcept>

#include <fcntl.h>
#include <unistd.h>
#include <zstd.h>

#include "mcap_bytes.hpp"
#include "navbus/records/mcap.hpp"

namespace navbus::records {

namespace {

constexpr int kZstdLevel = 3;  // zstd's default: most of the gain at a small cost

std::vector<std::uint8_t> record(std::uint8_t opcode, const std::vector<std::uint8_t>& content) {
  mcap::ByteWriter w;
  w.u8(opcode).u64(content.size()).raw(content);
  return std::move(w.bytes());
}

std::vector<std::uint8_t> schemaContent(const McapSchema& s) {
  mcap::ByteWriter w;
  w.u16(s.id).str(s.name).str(s.encoding).str(s.data);  // data: uint32-prefixed, as a string
  return std::move(w.bytes());
}

std::vector<std::uint8_t> channelContent(const McapChannel& c) {
  mcap::ByteWriter w;
  w.u16(c.id).u16(c.schema_id).str(c.topic).str(c.message_encoding).stringMap(c.metadata);
  return std::move(w.bytes());
}

std::vector<std::uint8_t> zstdCompress(const std::vector<std::uint8_t>& in) {
  std::vector<std::uint8_t> out(ZSTD_compressBound(in.size()));
  const std::size_t n = ZSTD_compress(out.data(), out.size(), in.data(), in.size(), kZstdLevel);
  if (ZSTD_isError(n)) {
    throw std::runtime_error(std::string("MCAP chunk: zstd compression failed: ") +
                             ZSTD_getErrorName(n));
  }
  out.resize(n);
  return out;
}

}  // namespace

McapWriter::McapWriter(const std::filesystem::path& file, McapWriterOptions options)
    : path_(file),
      fd_(::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644)),
      options_(std::move(options)) {
  if (fd_ < 0) failWrite("cannot create");
  writeBytes({std::begin(mcap::kMagic), std::end(mcap::kMagic)});
  mcap::ByteWriter header;
  header.str(options_.profile).str(options_.library);
  writeRecord(mcap::kHeader, header.bytes());
}

McapWriter::~McapWriter() {
  try {
    close();
  } catch (...) {  // a destructor must not throw; close() explicitly to see the error
  }
  if (fd_ >= 0) ::close(fd_);
}

void McapWriter::failWrite(const char* what) const {
  throw std::runtime_error(std::string(what) + " " + path_.string() + ": " + std::strerror(errno));
}

void McapWriter::writeBytes(const std::vector<std::uint8_t>& bytes) {
  for (std::size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) failWrite("cannot write");
    done += static_cast<std::size_t>(n);
  }
  running_crc_ = mcap::crc32Of(running_crc_, bytes.data(), bytes.size());
  offset_ += bytes.size();
}

void McapWriter::writeRecord(std::uint8_t opcode, const std::vector<std::uint8_t>& content) {
  writeBytes(record(opcode, content));
}

std::uint16_t McapWriter::addSchema(const std::string& name, const std::string& encoding,
                                    const std::string& data) {
  McapSchema s{static_cast<std::uint16_t>(schemas_.size() + 1), name, encoding, data};
  writeRecord(mcap::kSchema, schemaContent(s));
  schemas_.push_back(std::move(s));
  return schemas_.back().id;
}

std::uint16_t McapWriter::addChannel(std::uint16_t schema_id, const std::string& topic,
                                     const std::string& message_encoding,
                                     const std::map<std::string, std::string>& metadata) {
  if (schema_id == 0 || schema_id > schemas_.size()) {
    throw std::invalid_argument("MCAP channel '" + topic + "': no schema with id " +
                                std::to_string(schema_id));
  }
  McapChannel c{static_cast<std::uint16_t>(channels_.size()), schema_id, topic, message_encoding,
                metadata};
  writeRecord(mcap::kChannel, channelContent(c));
  channels_.push_back(std::move(c));
  channel_counts_.push_back(0);
  return channels_.back().id;
}

void McapWriter::addMetadata(const std::string& name,
                             const std::map<std::string, std::string>& metadata) {
  mcap::ByteWriter content;
  content.str(name).stringMap(metadata);
  const std::uint64_t start = offset_;
  writeRecord(mcap::kMetadata, content.bytes());
  mcap::ByteWriter index;
  index.u64(start).u64(offset_ - start).str(name);
  metadata_indexes_.push_back(std::move(index.bytes()));
}

void McapWriter::write(std::uint16_t channel_id, std::uint64_t log_time_ns,
                       std::uint64_t publish_time_ns, const std::vector<std::uint8_t>& data) {
  if (channel_id >= channels_.size()) {
    throw std::invalid_argument("MCAP message: no channel with id " + std::to_string(channel_id));
  }
  if (chunk_index_.empty()) {
    chunk_start_ns_ = chunk_end_ns_ = log_time_ns;
  }
  chunk_start_ns_ = std::min(chunk_start_ns_, log_time_ns);
  chunk_end_ns_ = std::max(chunk_end_ns_, log_time_ns);
  if (message_count_ == 0) start_ns_ = end_ns_ = log_time_ns;
  start_ns_ = std::min(start_ns_, log_time_ns);
  end_ns_ = std::max(end_ns_, log_time_ns);
  chunk_index_[channel_id].emplace_back(log_time_ns, chunk_.size());
  mcap::ByteWriter content;
  content.u16(channel_id)
      .u32(channel_counts_[channel_id]++)
      .u64(log_time_ns)
      .u64(publish_time_ns)
      .raw(data);
  const auto rec = record(mcap::kMessage, content.bytes());
  chunk_.insert(chunk_.end(), rec.begin(), rec.end());
  ++message_count_;
  ++pending_messages_;
  if (chunk_.size() >= options_.chunk_size_bytes) flushChunk();
}

void McapWriter::flush() {
  if (closed_ || pending_messages_ == 0) return;
  flushChunk();
  if (::fdatasync(fd_) != 0) failWrite("cannot write to the disk");
  pending_messages_ = 0;
}

void McapWriter::flushChunk() {
  if (chunk_index_.empty()) return;
  const bool zstd = options_.compression == McapCompression::kZstd;
  const std::string compression = zstd ? "zstd" : "";
  const std::vector<std::uint8_t> stored = zstd ? zstdCompress(chunk_) : chunk_;
  mcap::ByteWriter chunk;
  chunk.u64(chunk_start_ns_)
      .u64(chunk_end_ns_)
      .u64(chunk_.size())
      .u32(mcap::crc32Of(0, chunk_.data(), chunk_.size()))
      .str(compression)
      .u64(stored.size())
      .raw(stored);
  const std::uint64_t chunk_start = offset_;
  writeRecord(mcap::kChunk, chunk.bytes());
  const std::uint64_t chunk_length = offset_ - chunk_start;
  // One Message Index per channel with messages in the chunk, right after it.
  std::map<std::uint16_t, std::uint64_t> index_offsets;
  const std::uint64_t indexes_start = offset_;
  for (const auto& [channel, entries] : chunk_index_) {
    mcap::ByteWriter index;
    index.u16(channel).u32(static_cast<std::uint32_t>(entries.size() * 16));
    for (const auto& [log_ns, at] : entries) index.u64(log_ns).u64(at);
    index_offsets[channel] = offset_;
    writeRecord(mcap::kMessageIndex, index.bytes());
  }
  mcap::ByteWriter chunk_index;
  chunk_index.u64(chunk_start_ns_)
      .u64(chunk_end_ns_)
      .u64(chunk_start)
      .u64(chunk_length)
      .idMap(index_offsets)
      .u64(offset_ - indexes_start)
      .str(compression)
      .u64(stored.size())
      .u64(chunk_.size());
  chunk_indexes_.push_back(std::move(chunk_index.bytes()));
  ++chunk_count_;
  chunk_.clear();
  chunk_index_.clear();
}

void McapWriter::close() {
  if (closed_) return;
  closed_ = true;
  flushChunk();
  mcap::ByteWriter data_end;
  data_end.u32(running_crc_);
  writeRecord(mcap::kDataEnd, data_end.bytes());
  writeSummary();
  const int fd = fd_;
  fd_ = -1;
  const bool synced = ::fdatasync(fd) == 0;
  const int sync_errno = errno;
  if (::close(fd) != 0 || !synced) {
    if (!synced) errno = sync_errno;
    failWrite("cannot close");
  }
}

void McapWriter::writeSummary() {
  // The summary, grouped by opcode, each group's place noted for the Summary Offset records.
  const std::uint64_t summary_start = offset_;
  std::vector<std::pair<std::uint8_t, std::pair<std::uint64_t, std::uint64_t>>> groups;
  const auto group = [&](std::uint8_t opcode, const std::vector<std::vector<std::uint8_t>>& items) {
    if (items.empty()) return;
    const std::uint64_t start = offset_;
    for (const auto& content : items) writeRecord(opcode, content);
    groups.push_back({opcode, {start, offset_ - start}});
  };
  // The data section's CRC is in Data End; the summary's starts here.
  running_crc_ = 0;
  std::vector<std::vector<std::uint8_t>> schemas, channels;
  for (const auto& s : schemas_) schemas.push_back(schemaContent(s));
  for (const auto& c : channels_) channels.push_back(channelContent(c));
  group(mcap::kSchema, schemas);
  group(mcap::kChannel, channels);
  mcap::ByteWriter stats;
  std::map<std::uint16_t, std::uint64_t> counts;
  for (std::size_t c = 0; c < channel_counts_.size(); ++c) {
    counts[static_cast<std::uint16_t>(c)] = channel_counts_[c];
  }
  stats.u64(message_count_)
      .u16(static_cast<std::uint16_t>(schemas_.size()))
      .u32(static_cast<std::uint32_t>(channels_.size()))
      .u32(0)
      .u32(static_cast<std::uint32_t>(metadata_indexes_.size()))
      .u32(chunk_count_)
      .u64(start_ns_)
      .u64(end_ns_)
      .idMap(counts);
  group(mcap::kStatistics, {stats.bytes()});
  group(mcap::kChunkIndex, chunk_indexes_);
  group(mcap::kMetadataIndex, metadata_indexes_);
  const std::uint64_t summary_offset_start = offset_;
  for (const auto& [opcode, place] : groups) {
    mcap::ByteWriter offset;
    offset.u8(opcode).u64(place.first).u64(place.second);
    writeRecord(mcap::kSummaryOffset, offset.bytes());
  }
  // Footer: the summary CRC covers everything from the summary's start through
  // summary_offset_start, the footer's opcode and length included.
  mcap::ByteWriter footer_head;
  footer_head.u8(mcap::kFooter).u64(20).u64(summary_start).u64(summary_offset_start);
  const std::uint32_t summary_crc =
      mcap::crc32Of(running_crc_, footer_head.bytes().data(), footer_head.bytes().size());
  footer_head.u32(summary_crc);
  writeBytes(footer_head.bytes());
  writeBytes({std::begin(mcap::kMagic), std::end(mcap::kMagic)});
}

}  // namespace navbus::records
