#include "navbus/records/csv_table.hpp"

#include <csv.h>

#include <fstream>

#include "navbus/bus/config.hpp"

namespace navbus::records {

namespace {

/// libcsv's callbacks collect the cells of the current row, then the row.
struct Collector {
  CsvTable* table;
  std::vector<std::string> row;
  std::size_t line{0};
  std::string error;
};

void onCell(void* data, std::size_t size, void* user) {
  auto* c = static_cast<Collector*>(user);
  c->row.emplace_back(static_cast<const char*>(data), size);
}

void onRow(int, void* user) {
  auto* c = static_cast<Collector*>(user);
  ++c->line;
  if (c->line == 1) {
    c->table->header = std::move(c->row);
  } else if (c->error.empty() && c->row.size() != c->table->header.size()) {
    c->error = "line " + std::to_string(c->line) + " has " + std::to_string(c->row.size()) +
               " cells, the header " + std::to_string(c->table->header.size());
  } else {
    c->table->rows.push_back(std::move(c->row));
  }
  c->row.clear();
}

}  // namespace

std::size_t CsvTable::column(const std::string& name) const {
  const auto it = index.find(name);
  if (it != index.end()) return it->second;
  throw bus::ConfigError(file + ": no column '" + name + "'");
}

CsvTable readCsv(const std::filesystem::path& path) {
  CsvTable table;
  table.file = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw bus::ConfigError(table.file + ": cannot be read");
  csv_parser parser{};
  if (csv_init(&parser, CSV_STRICT | CSV_STRICT_FINI) != 0) {
    throw bus::ConfigError("libcsv: cannot initialize its parser");
  }
  Collector collector{&table, {}, 0, {}};
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
    throw bus::ConfigError(table.file + ": not CSV after line " + std::to_string(collector.line) +
                           " (" + why + ")");
  }
  if (!collector.error.empty()) throw bus::ConfigError(table.file + ": " + collector.error);
  if (table.header.empty()) throw bus::ConfigError(table.file + ": no header line");
  for (std::size_t i = 0; i < table.header.size(); ++i) table.index.emplace(table.header[i], i);
  return table;
}

}  // namespace navbus::records
