#include "navbus/core/integrity/glr_protection_level.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <boost/math/distributions/non_central_chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>

#include "navbus/core/ins/state_layout.hpp"

namespace navbus::core {

namespace {

/// k with P(|x| > k sigma) = p for a Gaussian x (doc eq. PL4).
double twoSidedGaussianFactor(double p) {
  return boost::math::quantile(
      boost::math::complement(boost::math::normal_distribution<>{}, p / 2));
}

/// k with P(|x| > k sigma_major) <= p for a horizontal Gaussian error whose larger principal
/// standard deviation is sigma_major: |x|^2 / sigma_major^2 is at most chi-square(2), whose
/// tail is exp(-k^2 / 2) (doc eq. PL5).
double horizontalFactor(double p) {
  return std::sqrt(-2.0 * std::log(p));
}

}  // namespace

double minimumDetectableSigmas(int dof, double threshold, double missed_detection_probability) {
  using Dist = boost::math::non_central_chi_squared_distribution<double>;
  return std::sqrt(Dist::find_non_centrality(dof, 2.0 * threshold, missed_detection_probability));
}

void toGlrEpoch(std::int64_t time_ns, const EpochDiagnostics& d, GlrEpoch& out) {
  const auto m = std::min<Eigen::Index>(d.h.rows(), glr::kMaxRows);
  out.time_ns = time_ns;
  out.rows = static_cast<int>(m);
  for (Eigen::Index r = 0; r < m; ++r) {
    out.sv_id[static_cast<std::size_t>(r)] = d.sv_ids[static_cast<std::size_t>(r)];
    out.is_rate[static_cast<std::size_t>(r)] = d.is_rate[static_cast<std::size_t>(r)];
    out.receiver[static_cast<std::size_t>(r)] = static_cast<std::size_t>(r) < d.receivers.size()
                                                    ? d.receivers[static_cast<std::size_t>(r)]
                                                    : 0;
  }
  out.innovation = d.innovation.head(m);
  out.innovation_cov = d.innovation_cov.topLeftCorner(m, m);
  out.h = d.h.topRows(m);
  out.k = d.k.leftCols(m);
  out.phi = d.phi;
}

GlrProtectionLevel::GlrProtectionLevel() {
  configure(IntegrityConfig{});
}

void GlrProtectionLevel::configure(const IntegrityConfig& config) {
  config_ = config;
  monitor_.reset();
  if (!config.enabled) {
    reset();
    return;
  }
  monitor_.emplace(config.detector);
  reserveSignatures();
  // The group statistics have as many degrees of freedom as the rank of their directions (up
  // to 6 for the IMU, 3 per satellite), and against the one threshold h a lower rank needs the
  // larger noncentrality: rank 1, the largest, bounds every group (within 2.2 % of rank 6 at
  // h = 35.7, P_md = 1e-3; doc eq. PL2).
  detectable_sigmas_ =
      minimumDetectableSigmas(1, config.detector.threshold, config.missed_detection_probability);
  k_ff_h_ = horizontalFactor(config.integrity_risk / 2.0);
  k_ff_v_ = twoSidedGaussianFactor(config.integrity_risk / 2.0);
  k_md_h_ = horizontalFactor(config.missed_detection_probability);
  k_md_v_ = twoSidedGaussianFactor(config.missed_detection_probability);
  reset();
}

void GlrProtectionLevel::reserveSignatures() {
  const GlrConfig& c = monitor_->config();
  const auto n = static_cast<std::size_t>(glr::directions(glrSlotCapacity(c)) * c.window);
  if (signatures_->capacity() < n) signatures_->reserve(n);
}

void GlrProtectionLevel::reset() {
  if (monitor_) monitor_->reset();
  have_biases_ = false;
  biases_ = FaultBiases{};
}

void GlrProtectionLevel::onEpoch(std::int64_t time_ns, const EpochDiagnostics& epoch) {
  if (!monitor_) return;
  toGlrEpoch(time_ns, epoch, *epoch_);
  const GlrResult& result = monitor_->update(*epoch_);
  if (!result.valid) return;  // refused: counted by the monitor
  detections_ += result.detected ? 1 : 0;
  reserveSignatures();
  monitor_->positionSignatures(*signatures_);
  biases_ = FaultBiases{};
  have_biases_ = !signatures_->empty();
  for (const auto& s : *signatures_) {
    // Minimum detectable magnitude nu = sqrt(lambda / R*) (doc eq. PL2) and the position
    // error it leaves after this epoch's update, nu mu+ (eq. PL3).
    if (!(s.information > 0.0)) continue;  // the data cannot see it: reported by the monitor
    const Eigen::Vector3d bias = detectable_sigmas_ / std::sqrt(s.information) * s.position_ned;
    biases_.horizontal_m = std::max(biases_.horizontal_m, bias.head<2>().norm());
    biases_.vertical_m = std::max(biases_.vertical_m, std::abs(bias.z()));
  }
}

ProtectionLevels GlrProtectionLevel::levels(const Eigen::Matrix3d& pos_cov_ned) const {
  ProtectionLevels out;
  if (!config_.enabled) return out;
  const Eigen::Matrix2d horizontal = pos_cov_ned.topLeftCorner<2, 2>();
  const double sigma_major = std::sqrt(std::max(
      0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(horizontal, Eigen::EigenvaluesOnly)
               .eigenvalues()
               .maxCoeff()));
  const double sigma_down = std::sqrt(std::max(0.0, pos_cov_ned(2, 2)));
  // Fault-free against every fault hypothesis (eq. PL3), the larger of the two (doc: the levels).
  out.horizontal_m = k_ff_h_ * sigma_major;
  out.vertical_m = k_ff_v_ * sigma_down;
  if (have_biases_) {
    out.horizontal_m = std::max(out.horizontal_m, biases_.horizontal_m + k_md_h_ * sigma_major);
    out.vertical_m = std::max(out.vertical_m, biases_.vertical_m + k_md_v_ * sigma_down);
  }
  if (!have_biases_) {
    out.state = IntegrityState::kInitializing;
  } else {
    out.state = out.horizontal_m <= config_.horizontal_alert_limit_m &&
                        out.vertical_m <= config_.vertical_alert_limit_m
                    ? IntegrityState::kAvailable
                    : IntegrityState::kUnavailable;
  }
  return out;
}

}  // namespace navbus::core
