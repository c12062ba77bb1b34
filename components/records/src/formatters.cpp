#include "navbus/records/formatters.hpp"

#include <fmt/format.h>

namespace navbus::records {

std::string formatNumber(double v) {
  // fmt's default for a double is the shortest text that reads back to the same bits
  // (0.0098066500000000001 with %.17g is 0.00980665 here).
  return fmt::format("{}", v);
}

std::string csvQuote(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char ch : s) {
    if (ch == '"') out += '"';
    out += ch;
  }
  return out + "\"";
}

std::vector<std::string> CellCollector::header() const {
  if (rows_at_ == static_cast<std::size_t>(-1)) return names_;
  std::vector<std::string> out(names_.begin(), names_.begin() + static_cast<long>(rows_at_));
  out.insert(out.end(), row_names_.begin(), row_names_.end());
  out.insert(out.end(), names_.begin() + static_cast<long>(rows_at_), names_.end());
  return out;
}

std::vector<std::vector<std::string>> CellCollector::rowsOut() const {
  if (rows_at_ == static_cast<std::size_t>(-1)) return {cells_};
  std::vector<std::vector<std::string>> out;
  const std::vector<std::vector<std::string>> elements =
      row_cells_.empty()
          ? std::vector<std::vector<std::string>>{std::vector<std::string>(row_names_.size())}
          : row_cells_;
  for (const auto& e : elements) {
    std::vector<std::string> row(cells_.begin(), cells_.begin() + static_cast<long>(rows_at_));
    row.insert(row.end(), e.begin(), e.end());
    row.insert(row.end(), cells_.begin() + static_cast<long>(rows_at_), cells_.end());
    out.push_back(std::move(row));
  }
  return out;
}

std::string joinCsv(const std::vector<std::string>& cells) {
  std::string out;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    if (i) out += ',';
    out += cells[i];
  }
  return out;
}

}  // namespace navbus::records
