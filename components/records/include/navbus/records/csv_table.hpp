// A CSV file read whole (libcsv, RFC 4180 quoting): the header and the rows as text cells.
#pragma once

#include <filesystem>
#include <string>
#include <unordered_map>
#include <vector>

namespace navbus::records {

struct CsvTable {
  std::string file;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;          ///< every row has header.size() cells
  std::unordered_map<std::string, std::size_t> index;  ///< column of each header name

  bool has(const std::string& name) const { return index.count(name) != 0; }

  /// Index of a column; throws bus::ConfigError naming the file and the column if absent.
  std::size_t column(const std::string& name) const;
};

/// One row of a CSV file as text cells, with its 1-based row number.
struct CsvRow {
  std::size_t line{0};
  std::vector<std::string> cells;
};

/// Every row of a CSV file, header or not, whatever its cell count (a logger's file, whose
/// first and last lines may be cut). Throws bus::ConfigError naming the file and the line if it
/// cannot be read or is not CSV.
std::vector<CsvRow> readCsvRows(const std::filesystem::path& path);

/// Throws bus::ConfigError (navbus/bus/config.hpp) naming the file (and the line) if it cannot be
/// read, is not CSV, or a row's cell count differs from the header's.
CsvTable readCsv(const std::filesystem::path& path);

}  // namespace navbus::records
