// Text and CSV renderings of navbus messages, driven by visitFields().
#pragma once

#include <array>
#include <cstdio>
#include <fstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <fmt/compile.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <fastrtps/utils/fixed_size_string.hpp>

#include "navbus/records/message_fields.hpp"

namespace navbus::records {

/// Shortest text that reads back to the same double (17 significant digits).
std::string formatNumber(double v);
std::string csvQuote(const std::string& s);

/// Collects the cells (or the column names) of one message.
class CellCollector {
 public:
  explicit CellCollector(std::string prefix = "") : prefix_(std::move(prefix)) {}

  template <class T>
  void operator()(const std::string& name, const T& value) {
    if constexpr (std::is_enum_v<T>) {
      add(name, enumName(value));
    } else if constexpr (std::is_same_v<T, bool>) {
      add(name, value ? "1" : "0");
    } else if constexpr (std::is_floating_point_v<T>) {
      add(name, formatNumber(value));
    } else if constexpr (std::is_integral_v<T>) {
      add(name, std::to_string(value));
    } else if constexpr (std::is_same_v<T, std::string>) {
      add(name, csvQuote(value));
    } else if constexpr (std::is_same_v<T, std::vector<double>>) {
      std::string joined;
      for (std::size_t i = 0; i < value.size(); ++i)
        joined += (i ? ";" : "") + formatNumber(value[i]);
      add(name, joined);
    } else {  // std::array<double, N>
      for (std::size_t i = 0; i < value.size(); ++i)
        add(name + "[" + std::to_string(i) + "]", formatNumber(value[i]));
    }
  }
  /// Bounded IDL strings (string<N>) are fixed_string<N> in the generated C++.
  template <std::size_t N>
  void operator()(const std::string& name, const eprosima::fastrtps::fixed_string<N>& value) {
    add(name, csvQuote(value.to_string()));
  }
  void text(const std::string& name, const std::string& s) { add(name, csvQuote(s)); }

  /// An element that has a sequence of structs itself (a block of GNSS epochs) gives a row
  /// per element of that one, its own cells repeated on each.
  template <class S>
  void rows(const std::string& name, const std::vector<S>& seq) {
    rows_at_ = cells_.size();
    CellCollector names(prefix_ + name + ".");
    const S empty{};
    visitFields(empty, names);
    row_names_ = names.header();
    for (const auto& element : seq) {
      CellCollector sub;
      visitFields(element, sub);
      for (auto& row : sub.rowsOut()) row_cells_.push_back(std::move(row));
    }
  }

  /// Column names, with the row fields in place of the sequence.
  std::vector<std::string> header() const;
  /// One row per element of the sequence (one row, its cells empty, if there is none).
  std::vector<std::vector<std::string>> rowsOut() const;

 private:
  void add(const std::string& name, const std::string& cell) {
    names_.push_back(prefix_ + name);
    cells_.push_back(cell);
  }
  std::string prefix_;
  std::vector<std::string> names_;
  std::vector<std::string> cells_;
  std::size_t rows_at_{static_cast<std::size_t>(-1)};
  std::vector<std::string> row_names_;
  std::vector<std::vector<std::string>> row_cells_;
};

std::string joinCsv(const std::vector<std::string>& cells);

/// Appends the CSV cells of one message to a buffer, comma-separated, with no names and no
/// string per cell: the fast path for large files (the offline solution file). The cells are
/// those of CellCollector. A message with a sequence of structs (several rows) is not written:
/// complete() is then false and the caller uses csvRows.
class CsvCellWriter {
 public:
  explicit CsvCellWriter(fmt::memory_buffer& out) : out_(out) {}

  template <class T>
  void operator()(std::string_view, const T& value) {
    separate();
    if constexpr (std::is_enum_v<T>) {
      append(enumName(value));
    } else if constexpr (std::is_same_v<T, bool>) {
      append(value ? "1" : "0");
    } else if constexpr (std::is_arithmetic_v<T>) {
      number(value);  // as formatNumber / to_string
    } else if constexpr (std::is_same_v<T, std::string>) {
      append(csvQuote(value));
    } else if constexpr (std::is_same_v<T, std::vector<double>>) {
      numbers(value, ';');
    } else {  // std::array<double, N>: a cell each
      numbers(value, ',');
    }
  }
  template <std::size_t N>
  void operator()(std::string_view, const eprosima::fastrtps::fixed_string<N>& value) {
    separate();
    append(csvQuote(value.to_string()));
  }
  void text(std::string_view, const std::string& s) {
    separate();
    append(csvQuote(s));
  }
  template <class S>
  void rows(std::string_view, const std::vector<S>&) {
    complete_ = false;
  }
  bool complete() const { return complete_; }

 private:
  void separate() {
    if (!first_) out_.push_back(',');
    first_ = false;
  }
  void append(std::string_view s) { out_.append(s.data(), s.data() + s.size()); }
  /// Shortest round-trip text ("{}"), the format compiled and written straight into the buffer
  /// (the runtime-parsed form through a back_inserter cost a third of the offline run's CSV time).
  template <class T>
  void number(T value) {
    fmt::format_to(fmt::appender(out_), FMT_COMPILE("{}"), value);
  }
  template <class Range>
  void numbers(const Range& values, char separator) {
    bool first = true;
    for (const auto v : values) {
      if (!first) out_.push_back(separator);
      first = false;
      number(v);
    }
  }
  fmt::memory_buffer& out_;
  bool first_{true};
  bool complete_{true};
};

/// Appends one message's CSV line (with its newline) to `out`; false, with `out` unchanged, for a
/// message with a sequence of structs (use csvRows).
template <class T>
bool appendCsvLine(const T& msg, fmt::memory_buffer& out) {
  const std::size_t size = out.size();
  CsvCellWriter w(out);
  visitFields(msg, w);
  if (!w.complete()) {
    out.resize(size);
    return false;
  }
  out.push_back('\n');
  return true;
}

template <class T>
std::string csvHeader() {
  CellCollector c;
  const T empty{};
  visitFields(empty, c);
  return joinCsv(c.header());
}

template <class T>
std::vector<std::string> csvRows(const T& msg) {
  CellCollector c;
  visitFields(msg, c);
  std::vector<std::string> out;
  for (const auto& r : c.rowsOut()) out.push_back(joinCsv(r));
  return out;
}

/// Writes messages of one type as a CSV file (header, then their rows); false if the file
/// could not be written.
template <class T>
bool writeCsvFile(const std::string& path, const std::vector<T>& messages) {
  std::ofstream f(path);
  f << csvHeader<T>() << "\n";
  for (const auto& m : messages)
    for (const auto& row : csvRows(m)) f << row << "\n";
  return static_cast<bool>(f);
}

/// "name: value" lines, sequences of structs indexed.
template <class T>
std::string textOf(const T& msg) {
  CellCollector c;
  visitFields(msg, c);
  const auto names = c.header();
  std::string out;
  const auto rows = c.rowsOut();
  for (std::size_t r = 0; r < rows.size(); ++r) {
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (r > 0 && names[i].find('.') == std::string::npos)
        continue;  // row-independent fields once
      out += names[i] +
             (rows.size() > 1 && names[i].find('.') != std::string::npos ? "#" + std::to_string(r)
                                                                         : "") +
             ": " + rows[r][i] + "\n";
    }
  }
  return out;
}

}  // namespace navbus::records
