#include "navbus/evaluation/coverage.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace navbus::evaluation {

namespace {
double share(std::size_t part, std::size_t whole) {
  return whole == 0 ? 0.0 : static_cast<double>(part) / static_cast<double>(whole);
}
}  // namespace

void CoverageTally::add(double error_h_m, double sigma_h_m, bool covariance_valid) {
  const double ratio = sigma_h_m > 0.0 ? error_h_m / sigma_h_m : HUGE_VAL;
  ratios_.push_back(ratio);
  for (int k = 1; k <= 3; ++k) inside_[static_cast<std::size_t>(k - 1)] += ratio <= k ? 1 : 0;
  if (!covariance_valid) {
    ++flagged_;
  } else if (ratio <= 3.0) {
    ++unflagged_inside3_;
  }
}

double CoverageTally::insideShare(int k) const {
  return share(inside_.at(static_cast<std::size_t>(k - 1)), epochs());
}

double CoverageTally::medianRatio() const {
  if (ratios_.empty()) return 0.0;
  std::vector<double> sorted = ratios_;
  const std::size_t n = sorted.size();
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(n / 2),
                   sorted.end());
  const double upper = sorted[n / 2];
  if (n % 2 == 1) return upper;
  const double lower =
      *std::max_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(n / 2));
  return 0.5 * (lower + upper);
}

double CoverageTally::flaggedShare() const {
  return share(flagged_, epochs());
}

double CoverageTally::unflaggedInside3Share() const {
  return share(unflagged_inside3_, epochs() - flagged_);
}

double consistentShare(int k) {
  return 1.0 - std::exp(-static_cast<double>(k * k));
}

std::string coverageHeader() {
  return "                          epochs  inside 1 / 2 / 3 sigma_h [%]  median e/sigma_h  "
         "flagged [%]  unflagged inside 3 sigma_h [%]\n";
}

std::string coverageRow(const std::string& label, const CoverageTally& t, bool flags) {
  const std::string flagged =
      flags ? fmt::format("{:11.1f}", 100.0 * t.flaggedShare()) : "          -";
  const std::string unflagged = flags ? fmt::format("{:30.1f}", 100.0 * t.unflaggedInside3Share())
                                      : std::string(29, ' ') + "-";
  return fmt::format("{:24}  {:6}  {:8.1f} {:6.1f} {:6.1f}        {:16.2f}  {}  {}\n", label,
                     t.epochs(), 100.0 * t.insideShare(1), 100.0 * t.insideShare(2),
                     100.0 * t.insideShare(3), t.medianRatio(), flagged, unflagged);
}

std::string coverageFooter() {
  return fmt::format("{:24}  {:6}  {:8.1f} {:6.1f} {:6.2f}        {:16.2f}\n",
                     "consistent (isotropic)", "", 100.0 * consistentShare(1),
                     100.0 * consistentShare(2), 100.0 * consistentShare(3),
                     kConsistentMedianRatio);
}

std::string coverageCsvLine(const std::string& run, const std::string& group,
                            const CoverageTally& t, bool flags) {
  std::string line =
      fmt::format("{},{},{},{:.4f},{:.4f},{:.4f},{:.4f},", run, group, t.epochs(), t.insideShare(1),
                  t.insideShare(2), t.insideShare(3), t.medianRatio());
  if (flags) {
    line += fmt::format("{:.4f},{:.4f}", t.flaggedShare(), t.unflaggedInside3Share());
  } else {
    line += ",";
  }
  return line + "\n";
}

}  // namespace navbus::evaluation
