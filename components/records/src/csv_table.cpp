#include "navbus/records/csv_table.hpp"

#include <csv.h>

#include <fstream>

#include "navbus/bus/config.hpp"

namespace navbus::records {

namespace {

/// libcsv's callbacks collect the cells of the current row, then the row.
struct Collector {
  std::vector<CsvRow>* rows;
  std::vector<std::string> cells;
};

void onCell(void* data, std::size_t size, void* user) {
  auto* c = static_cast<Collector*>(user);
  c->cells.emplace_back(static_cast<const char*>(data), size);
}

void onRow(int, void* user) {
  auto* c = static_cast<Collector*>(user);
  c->rows->push_back({c->rows->size() + 1, std::move(c->cells)});
  c->cells.clear();
}

}  // namespace

std::size_t CsvTable::column(const std::string& name) const {
  const auto it = index.find(name);
  if (it != index.end()) return it->second;
  throw bus::ConfigError(file + ": no column '" + name + "'");
}

std::vector<CsvRow> readCsvRows(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw bus::ConfigError(path.string() + ": cannot be read");
  csv_parser parser{};
  if (csv_init(&parser, CSV_STRICT | CSV_STRICT_FINI) != 0) {
    throw bus::ConfigError("libcsv: cannot initialize its parser");
  }
  std::vector<CsvRow> rows;
  Collector collector{&rows, {}};
  char buffer[1 << 16];
  bool parsed = true;
  while (parsed && in) {
    in.read(buffer, sizeof buffer);
    const auto n = static_cast<std::size_t>(in.gcount());
    parsed = csv_parse(&parser, buffer, n, onCell, onRow, &collector) == n;
  }
  parsed = parsed && csv_fini(&parser, onCell, onRow, &collector) == 0;
  const std::string why = parsed ? "" : csv_strerror(csv_error(&parser));
  csv_free(&parser);
  if (!parsed) {
    throw bus::ConfigError(path.string() + ": not CSV after line " + std::to_string(rows.size()) +
                           " (" + why + ")");
  }
  return rows;
}

CsvTable readCsv(const std::filesystem::path& path) {
  CsvTable table;
  table.file = path.string();
  std::vector<CsvRow> rows = readCsvRows(path);
  if (rows.empty()) throw bus::ConfigError(table.file + ": no header line");
  table.header = std::move(rows.front().cells);
  table.rows.reserve(rows.size() - 1);
  for (std::size_t i = 1; i < rows.size(); ++i) {
    if (rows[i].cells.size() != table.header.size()) {
      throw bus::ConfigError(table.file + ": line " + std::to_string(rows[i].line) + " has " +
                             std::to_string(rows[i].cells.size()) + " cells, the header " +
                             std::to_string(table.header.size()));
    }
    table.rows.push_back(std::move(rows[i].cells));
  }
  for (std::size_t i = 0; i < table.header.size(); ++i) table.index.emplace(table.header[i], i);
  return table;
}

}  // namespace navbus::records
