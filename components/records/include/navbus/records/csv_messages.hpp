// Messages read back from the CSV files `navbus record` writes: the same field lists
// (message_fields.hpp) visited on a message to fill, the same columns (formatters.hpp's
// CellCollector: arrays as name[i], a sequence of structs as one row per element with columns
// "<sequence>.<field>", enums by name, doubles in shortest round-trip form, so a replayed
// message is bit-identical to the recorded one). What `navbus replay` publishes.
#pragma once

#include <charconv>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "navbus/bus/config.hpp"
#include "navbus/records/csv_table.hpp"
#include "navbus/records/message_fields.hpp"

namespace navbus::records {

/// The enumerator whose enumName() is `name`; throws bus::ConfigError naming `where`.
template <class E>
E enumFromName(const std::string& name, const std::string& where) {
  // IDL enumerators are numbered from 0 without gaps; enumName() of any other value is UNKNOWN.
  std::string known;
  for (int i = 0; i < 256 && std::string(enumName(static_cast<E>(i))) != "UNKNOWN"; ++i) {
    if (name == enumName(static_cast<E>(i))) return static_cast<E>(i);
    known += std::string(i == 0 ? "" : ", ") + enumName(static_cast<E>(i));
  }
  throw bus::ConfigError(where + ": '" + name + "' is not one of " + known);
}

/// Rows [first, first + count) of a table in groups of consecutive rows whose cells in the
/// columns `prefix` + a field name (no further '.') are equal: the rows of one struct, its own
/// fields repeated on each row of its sequence of structs (a message, or a block's epoch).
/// (first row, rows) per group.
std::vector<std::pair<std::size_t, std::size_t>> rowGroups(const CsvTable& table, std::size_t first,
                                                           std::size_t count,
                                                           const std::string& prefix);

/// Fills the fields of one message from the rows [first, first + count) of a table.
class CellParser {
 public:
  CellParser(const CsvTable& table, std::size_t first, std::size_t count, std::string prefix = "")
      : table_(table), first_(first), count_(count), prefix_(std::move(prefix)) {}

  template <class T>
  void operator()(const std::string& name, T& value) {
    if constexpr (std::is_enum_v<T>) {
      value = enumFromName<T>(cell(name), where(name));
    } else if constexpr (std::is_same_v<T, bool>) {
      value = parseNumber<int>(name, cell(name)) != 0;
    } else if constexpr (std::is_arithmetic_v<T>) {
      value = parseNumber<T>(name, cell(name));
    } else if constexpr (std::is_same_v<T, std::string>) {
      value = cell(name);
    } else if constexpr (std::is_same_v<T, std::vector<double>>) {
      value.clear();
      const std::string& text = cell(name);
      for (std::size_t start = 0; start < text.size();) {
        const std::size_t end = std::min(text.find(';', start), text.size());
        value.push_back(parseNumber<double>(name, text.substr(start, end - start)));
        start = end + 1;
      }
    } else {  // std::array<double, N>
      for (std::size_t i = 0; i < value.size(); ++i) {
        const std::string element = name + "[" + std::to_string(i) + "]";
        value[i] = parseNumber<double>(element, cell(element));
      }
    }
  }
  template <std::size_t N>
  void operator()(const std::string& name, eprosima::fastrtps::fixed_string<N>& value) {
    const std::string& text = cell(name);
    if (text.size() > N) {
      throw bus::ConfigError(where(name) + ": '" + text + "' is longer than " + std::to_string(N) +
                             " characters");
    }
    value = text;
  }
  void text(const std::string& name, const std::string&) {
    throw bus::ConfigError(where(name) +
                           " is recorded as a summary, not field by field: this topic cannot be "
                           "replayed");
  }
  /// One element per row; a single row whose cells of the sequence are empty is no element. An
  /// element with a sequence of structs of its own spans the consecutive rows whose cells of
  /// its other fields are equal (CellCollector::rows).
  template <class S>
  void rows(const std::string& name, std::vector<S>& seq) {
    seq.clear();
    const std::string element_prefix = prefix_ + name + ".";
    HasRows nested;
    const S probe{};
    visitFields(probe, nested);
    for (const auto& [r, n] :
         nested.found ? rowGroups(table_, first_, count_, element_prefix) : singleRows()) {
      if (count_ == 1 && rowIsEmpty(r, element_prefix)) break;
      CellParser element_parser(table_, r, n, element_prefix);
      S element;
      visitFields(element, element_parser);
      seq.push_back(element);
    }
  }

 private:
  const std::string& cell(const std::string& name) const {
    return table_.rows[first_][table_.column(prefix_ + name)];
  }
  std::string where(const std::string& name) const {
    return table_.file + " line " + std::to_string(first_ + 2) + " column '" + prefix_ + name + "'";
  }
  /// Whether a struct holds a sequence of structs.
  struct HasRows {
    bool found{false};
    template <class T>
    void operator()(const std::string&, const T&) {}
    void text(const std::string&, const std::string&) {}
    template <class S>
    void rows(const std::string&, const std::vector<S>&) {
      found = true;
    }
  };
  /// Each of this parser's rows on its own: (row, 1).
  std::vector<std::pair<std::size_t, std::size_t>> singleRows() const {
    std::vector<std::pair<std::size_t, std::size_t>> rows;
    for (std::size_t r = first_; r < first_ + count_; ++r) rows.emplace_back(r, 1);
    return rows;
  }
  bool rowIsEmpty(std::size_t row, const std::string& element_prefix) const {
    for (std::size_t c = 0; c < table_.header.size(); ++c) {
      if (table_.header[c].rfind(element_prefix, 0) == 0 && !table_.rows[row][c].empty()) {
        return false;
      }
    }
    return true;
  }
  template <class T>
  T parseNumber(const std::string& name, const std::string& text) const {
    T value{};
    const char* end = text.data() + text.size();
    auto [ptr, ec] = std::from_chars(text.data(), end, value);
    if (ec != std::errc() || ptr != end) {
      throw bus::ConfigError(where(name) + ": '" + text + "' is not a valid number");
    }
    return value;
  }

  const CsvTable& table_;
  std::size_t first_, count_;
  std::string prefix_;
};

/// Rows [first, first + count) of the table belong to one message when their cells outside the
/// sequence columns (names with a '.') are equal: the scalar fields repeated on each row.
std::vector<std::pair<std::size_t, std::size_t>> messageRowRanges(const CsvTable& table);

/// Every message of a recorded file, in file order, from its rows' ranges (messageRowRanges).
template <class T>
std::vector<T> parseMessages(const CsvTable& table,
                             const std::vector<std::pair<std::size_t, std::size_t>>& ranges) {
  std::vector<T> messages;
  for (const auto& [first, count] : ranges) {
    CellParser parser(table, first, count);
    T message;
    visitFields(message, parser);
    messages.push_back(message);
  }
  return messages;
}

}  // namespace navbus::records
