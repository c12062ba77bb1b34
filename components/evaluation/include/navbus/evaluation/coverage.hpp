// How honest a run's sigmas are on real data: over a set of judged epochs, the share whose
// horizontal error e lies inside 1, 2 and 3 of the solution's own sigma_h = sqrt(sN^2 + sE^2),
// the median of e / sigma_h, the share the filter itself flagged (covariance_valid false) and
// the 3-sigma_h share of the epochs it did not flag. For a consistent filter with an isotropic
// horizontal error, e^2 / (sigma_h^2 / 2) is chi-square with 2 degrees of freedom, so
// P(e <= k sigma_h) = 1 - exp(-k^2): 63.2 %, 98.2 % and 99.99 %, and the median of e / sigma_h
// is sqrt(ln 2) = 0.83 (consistentShare, kConsistentMedianRatio).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace navbus::evaluation {

class CoverageTally {
 public:
  /// One epoch: its horizontal error and 1-sigma [m], and whether the solution claimed its
  /// covariance valid. An epoch with sigma_h not positive counts as outside every bound.
  void add(double error_h_m, double sigma_h_m, bool covariance_valid);

  std::size_t epochs() const { return ratios_.size(); }
  /// Share of the epochs with e <= k sigma_h, k = 1, 2, 3 (0 without epochs).
  double insideShare(int k) const;
  double medianRatio() const;   ///< median of e / sigma_h (0 without epochs)
  double flaggedShare() const;  ///< covariance_valid false
  /// Of the epochs not flagged, the share inside 3 sigma_h (0 without such epochs).
  double unflaggedInside3Share() const;
  std::size_t flagged() const { return flagged_; }

 private:
  std::vector<double> ratios_;  ///< e / sigma_h per epoch
  std::array<std::size_t, 3> inside_{};
  std::size_t flagged_{0};
  std::size_t unflagged_inside3_{0};
};

/// P(e <= k sigma_h) for a consistent isotropic horizontal error: 1 - exp(-k^2).
double consistentShare(int k);
inline constexpr double kConsistentMedianRatio = 0.8325546111576977;  ///< sqrt(ln 2)

/// One line of the honesty table: `label`, epochs, inside 1/2/3 sigma_h [%], median ratio,
/// flagged [%] and the unflagged 3-sigma_h share [%] ("-" where `flags` is false: a run
/// without its own validity flag, such as the smoother's).
std::string coverageRow(const std::string& label, const CoverageTally& t, bool flags);
/// The table's header and its last line (what a consistent filter gives).
std::string coverageHeader();
std::string coverageFooter();
/// The same as a CSV line: run,group,epochs,inside_1,inside_2,inside_3,median,flagged,
/// unflagged_3 (shares as fractions; flagged columns empty where `flags` is false).
std::string coverageCsvLine(const std::string& run, const std::string& group,
                            const CoverageTally& t, bool flags);
inline constexpr const char* kCoverageCsvHeader =
    "run,group,epochs,inside_1sigma_h,inside_2sigma_h,inside_3sigma_h,median_error_over_sigma_h,"
    "flagged,unflagged_inside_3sigma_h\n";

}  // namespace navbus::evaluation
