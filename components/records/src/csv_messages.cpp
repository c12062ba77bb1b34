#include "navbus/records/csv_messages.hpp"

namespace navbus::records {

std::vector<std::pair<std::size_t, std::size_t>> messageRowRanges(const CsvTable& table) {
  std::vector<std::size_t> scalar_columns;
  for (std::size_t c = 0; c < table.header.size(); ++c) {
    if (table.header[c].find('.') == std::string::npos) scalar_columns.push_back(c);
  }
  const auto sameMessage = [&](std::size_t a, std::size_t b) {
    for (std::size_t c : scalar_columns) {
      if (table.rows[a][c] != table.rows[b][c]) return false;
    }
    return true;
  };
  std::vector<std::pair<std::size_t, std::size_t>> ranges;
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    if (!ranges.empty() && sameMessage(ranges.back().first, r)) {
      ++ranges.back().second;
    } else {
      ranges.emplace_back(r, 1);
    }
  }
  return ranges;
}

}  // namespace navbus::records
