#include "navbus/records/csv_messages.hpp"

namespace navbus::records {

std::vector<std::pair<std::size_t, std::size_t>> rowGroups(const CsvTable& table, std::size_t first,
                                                           std::size_t count,
                                                           const std::string& prefix) {
  std::vector<std::size_t> own_columns;
  for (std::size_t c = 0; c < table.header.size(); ++c) {
    const std::string& column = table.header[c];
    if (column.rfind(prefix, 0) == 0 && column.find('.', prefix.size()) == std::string::npos)
      own_columns.push_back(c);
  }
  const auto sameGroup = [&](std::size_t a, std::size_t b) {
    for (std::size_t c : own_columns) {
      if (table.rows[a][c] != table.rows[b][c]) return false;
    }
    return true;
  };
  std::vector<std::pair<std::size_t, std::size_t>> groups;
  for (std::size_t r = first; r < first + count; ++r) {
    if (!groups.empty() && sameGroup(groups.back().first, r)) {
      ++groups.back().second;
    } else {
      groups.emplace_back(r, 1);
    }
  }
  return groups;
}

std::vector<std::pair<std::size_t, std::size_t>> messageRowRanges(const CsvTable& table) {
  return rowGroups(table, 0, table.rows.size(), "");
}

}  // namespace navbus::records
