#include "navbus/core/integrity/parity_glr.hpp"

#include <cmath>

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/non_central_chi_squared.hpp>

namespace navbus::core {

namespace {

bool probability(double p) {
  return p > 0.0 && p < 1.0;
}

}  // namespace

std::optional<ParityGlr> ParityGlr::make(const ParitySpace& space, const ParityGlrConfig& config,
                                         std::string& error) {
  const auto bad = [&](const std::string& key, double value, const char* range) {
    error = "parity GLR: " + key + " is " + std::to_string(value) + "; it must be " + range;
    return std::nullopt;
  };
  if (config.onsets < 1 || config.onsets > kMaxOnsets)
    return bad("onsets", config.onsets, "1 to 200");
  if (config.onset_spacing < 1) return bad("onset_spacing", config.onset_spacing, ">= 1");
  if (!probability(config.false_alarm_probability))
    return bad("false_alarm_probability", config.false_alarm_probability, "in (0, 1)");
  if (!probability(config.detection_probability))
    return bad("detection_probability", config.detection_probability, "in (0, 1)");
  return ParityGlr(space, config);
}

ParityGlr::ParityGlr(const ParitySpace& space, const ParityGlrConfig& config)
    : space_(space), config_(config) {
  const int n = space_.instruments();
  // Eq. 13's h: each sample runs n x onsets one-degree-of-freedom tests (Bonferroni).
  const double per_test = config_.false_alarm_probability / (n * config_.onsets);
  const boost::math::chi_squared_distribution<double> chi2(1.0);
  threshold_ = 0.5 * boost::math::quantile(boost::math::complement(chi2, per_test));
  // The noncentrality at which 2 l exceeds 2 h with the detection probability.
  detectable_noncentrality_ =
      boost::math::non_central_chi_squared_distribution<double>::find_non_centrality(
          1.0, 2.0 * threshold_, 1.0 - config_.detection_probability);
  for (int j = 0; j < n; ++j) information_[j] = space_.information(j);
  reset();
}

void ParityGlr::reset() {
  head_ = 0;
  count_ = 0;
  since_onset_ = 0;
  f_.setZero();
  samples_.fill(0);
  result_ = ParityGlrResult{};
  result_.threshold = threshold_;
}

double ParityGlr::minimumDetectableBias(int j) const {
  return std::sqrt(detectable_noncentrality_ / (windowSamples() * information_[j]));
}

const ParityGlrResult& ParityGlr::update(const parity::Measurements& m) {
  const int n = space_.instruments();
  if (since_onset_ == 0) {
    // A new hypothesised onset at this sample; the oldest leaves a full window.
    if (count_ == config_.onsets) {
      head_ = (head_ + 1) % config_.onsets;
      --count_;
    }
    const int ring = (head_ + count_++) % config_.onsets;
    f_.col(ring).setZero();
    samples_[static_cast<std::size_t>(ring)] = 0;
  }
  since_onset_ = (since_onset_ + 1) % config_.onset_spacing;
  // s_j^T p for every instrument (eqs. 2, 9).
  const parity::Vector p = space_.parityVector(m);
  const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, parity::kMaxInstruments, 1> u =
      space_.parityMatrix().transpose() * p;
  for (int i = 0; i < count_; ++i) {
    const int ring = (head_ + i) % config_.onsets;
    f_.col(ring).head(n) += u;
    ++samples_[static_cast<std::size_t>(ring)];
  }
  evaluate();
  return result_;
}

void ParityGlr::evaluate() {
  const int n = space_.instruments();
  result_ = ParityGlrResult{};
  result_.threshold = threshold_;
  int best_ring = -1;
  for (int i = 0; i < count_; ++i) {
    const int ring = (head_ + i) % config_.onsets;
    const double samples = samples_[static_cast<std::size_t>(ring)];
    for (int j = 0; j < n; ++j) {
      const double l = f_(j, ring) * f_(j, ring) / (2.0 * samples * information_[j]);  // eq. 12
      if (best_ring < 0 || l > result_.statistic) {
        result_.statistic = l;
        result_.instrument = j;
        best_ring = ring;
      }
    }
  }
  if (best_ring < 0) return;
  const int j = result_.instrument;
  const double samples = samples_[static_cast<std::size_t>(best_ring)];
  const double r = samples * information_[j];  // eq. 10
  // b^ of instrument i at that onset (eq. 11).
  auto magnitude = [&](int i) { return f_(i, best_ring) / (samples * information_[i]); };
  result_.detected = result_.statistic >= threshold_;
  result_.magnitude = magnitude(j);
  result_.magnitude_sigma = 1.0 / std::sqrt(r);
  result_.samples_since_onset = samples_[static_cast<std::size_t>(best_ring)];
  // Runner-up at the same onset: a collinear signature first (no data can tell them apart),
  // else the next largest statistic when it is within the margin.
  double runner_l = -1.0;
  for (int k = 0; k < n; ++k) {
    if (k == j) continue;
    if (space_.signatureCorrelation(j, k) >= config_.ambiguity_correlation) {
      result_.runner_up = k;
      result_.runner_up_magnitude = magnitude(k);
      result_.ambiguous = true;
      return;
    }
    const double l = f_(k, best_ring) * f_(k, best_ring) / (2.0 * samples * information_[k]);
    if (l > runner_l) {
      runner_l = l;
      result_.runner_up = k;
    }
  }
  result_.ambiguous = runner_l >= result_.statistic - config_.ambiguity_margin;
  if (!result_.ambiguous) {
    result_.runner_up = -1;
    return;
  }
  result_.runner_up_magnitude = magnitude(result_.runner_up);
}

}  // namespace navbus::core
