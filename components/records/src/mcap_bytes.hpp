// MCAP's record opcodes and its primitive encodings (little-endian integers, uint32-length
// prefixed strings and maps, uint64-length prefixed byte fields): mcap.dev/spec, Serialization.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <zlib.h>

namespace navbus::records::mcap {

inline constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

enum Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

/// A record's name as the specification gives it ("" for opcode 0: no record).
inline const char* recordName(std::uint8_t opcode) {
  switch (opcode) {
    case 0:
      return "";
    case kHeader:
      return "Header";
    case kFooter:
      return "Footer";
    case kSchema:
      return "Schema";
    case kChannel:
      return "Channel";
    case kMessage:
      return "Message";
    case kChunk:
      return "Chunk";
    case kMessageIndex:
      return "Message Index";
    case kChunkIndex:
      return "Chunk Index";
    case kAttachment:
      return "Attachment";
    case kAttachmentIndex:
      return "Attachment Index";
    case kStatistics:
      return "Statistics";
    case kMetadata:
      return "Metadata";
    case kMetadataIndex:
      return "Metadata Index";
    case kSummaryOffset:
      return "Summary Offset";
    case kDataEnd:
      return "Data End";
    default:
      return "private or unknown record";
  }
}

/// CRC-32 (zlib's, as the specification's) of `size` bytes, continuing from `crc`.
inline std::uint32_t crc32Of(std::uint32_t crc, const std::uint8_t* data, std::size_t size) {
  while (size > 0) {  // zlib takes uInt lengths: pieces below 4 GiB
    const auto n = static_cast<uInt>(std::min<std::size_t>(size, std::size_t{1} << 30));
    crc = static_cast<std::uint32_t>(::crc32(crc, data, n));
    data += n;
    size -= n;
  }
  return crc;
}

/// Bytes of one record's content, appended field by field.
class ByteWriter {
 public:
  ByteWriter& u8(std::uint8_t v) {
    bytes_.push_back(v);
    return *this;
  }
  ByteWriter& u16(std::uint16_t v) { return little(v, 2); }
  ByteWriter& u32(std::uint32_t v) { return little(v, 4); }
  ByteWriter& u64(std::uint64_t v) { return little(v, 8); }
  /// String: uint32 byte length, then the bytes.
  ByteWriter& str(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size()));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    return *this;
  }
  ByteWriter& raw(const std::vector<std::uint8_t>& b) {
    bytes_.insert(bytes_.end(), b.begin(), b.end());
    return *this;
  }
  /// Map<string, string>: uint32 byte length of the entries, then key, value, ... in key order.
  ByteWriter& stringMap(const std::map<std::string, std::string>& m) {
    ByteWriter entries;
    for (const auto& [k, v] : m) entries.str(k).str(v);
    return u32(static_cast<std::uint32_t>(entries.bytes_.size())).raw(entries.bytes_);
  }
  /// Map<uint16, uint64>.
  ByteWriter& idMap(const std::map<std::uint16_t, std::uint64_t>& m) {
    u32(static_cast<std::uint32_t>(m.size() * 10));
    for (const auto& [k, v] : m) u16(k).u64(v);
    return *this;
  }
  const std::vector<std::uint8_t>& bytes() const { return bytes_; }
  std::vector<std::uint8_t>& bytes() { return bytes_; }

 private:
  ByteWriter& little(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    return *this;
  }
  std::vector<std::uint8_t> bytes_;
};

/// Reads fields of one record's content; a field past its end throws, naming the field.
class ByteReader {
 public:
  /// `fail(field)` must throw.
  template <class Fail>
  ByteReader(const std::uint8_t* data, std::size_t size, Fail fail)
      : data_(data), size_(size), fail_(std::move(fail)) {}

  std::uint8_t u8(const char* field) { return static_cast<std::uint8_t>(little(field, 1)); }
  std::uint16_t u16(const char* field) { return static_cast<std::uint16_t>(little(field, 2)); }
  std::uint32_t u32(const char* field) { return static_cast<std::uint32_t>(little(field, 4)); }
  std::uint64_t u64(const char* field) { return little(field, 8); }
  std::string str(const char* field) {
    const std::uint32_t n = u32(field);
    need(field, n);
    std::string s(reinterpret_cast<const char*>(data_ + pos_), n);
    pos_ += n;
    return s;
  }
  std::map<std::string, std::string> stringMap(const char* field) {
    const std::uint32_t n = u32(field);
    need(field, n);
    const std::size_t end = pos_ + n;
    std::map<std::string, std::string> m;
    while (pos_ < end) {
      std::string key = str(field);
      m[key] = str(field);
    }
    if (pos_ != end) fail_(field);
    return m;
  }
  /// `n` bytes as they are.
  const std::uint8_t* bytes(const char* field, std::uint64_t n) {
    need(field, n);
    const std::uint8_t* p = data_ + pos_;
    pos_ += static_cast<std::size_t>(n);
    return p;
  }
  std::size_t remaining() const { return size_ - pos_; }
  std::size_t position() const { return pos_; }

 private:
  void need(const char* field, std::uint64_t n) {
    if (n > size_ - pos_) fail_(field);
  }
  std::uint64_t little(const char* field, int n) {
    need(field, static_cast<std::uint64_t>(n));
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(data_[pos_ + i]) << (8 * i);
    pos_ += static_cast<std::size_t>(n);
    return v;
  }
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_{0};
  std::function<void(const char*)> fail_;
};

}  // namespace navbus::records::mcap
