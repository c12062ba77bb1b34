// Seed 000's generalized likelihood ratio test (eqs. 9-13) on the parity vector of redundant
// instruments (parity_space.hpp): a bias step b on instrument j from onset theta makes the
// whitened parity vectors p_k = s_j b + w_k (w_k white, unit covariance) for k >= theta, so
//
//   f_j(theta) = sum_{k >= theta} s_j^T p_k,   R_j(theta) = N(theta) |s_j|^2,            (9, 10)
//   b^ = f / R,   l_j(theta) = f^2 / (2 R),                                           (11, 12)
//
// with N(theta) the samples since the onset; a detection is l >= h (13) for some instrument and
// onset in the window. Onsets are hypothesised every `onset_spacing` samples (a fault begun
// between two is caught from the next one, a little later). Isolation names the instrument of
// the largest l at the onset of the detection, and the runner-up when the two cannot be told
// apart (collinear signatures, or statistics within `ambiguity_margin`).
//
// Threshold and minimum detectable bias: without fault, 2 l of one (instrument, onset) is
// chi-square with 1 degree of freedom, so h is set from the false-alarm probability per sample
// shared among the n x onsets tests (Bonferroni); with a bias b over the whole window, 2 l is
// noncentral chi-square with noncentrality b^2 R_j, and the minimum detectable bias of
// instrument j is the b whose probability of detection is `detection_probability`.
// Fixed-capacity storage: update() allocates nothing.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "navbus/core/integrity/parity_space.hpp"

namespace navbus::core {

struct ParityGlrConfig {
  int onsets{20};         ///< hypothesised onsets kept in the window
  int onset_spacing{10};  ///< samples between two hypothesised onsets
  /// Probability that a fault-free sample raises a detection (all instruments and onsets).
  double false_alarm_probability{1e-7};
  /// For the minimum detectable bias: the probability of detecting a bias of that size that
  /// has lasted the whole window.
  double detection_probability{0.999};
  /// Isolation: a runner-up within this many units of log-likelihood of the best is named too.
  double ambiguity_margin{2.0};
  /// Isolation: signatures at least this correlated cannot be told apart (|cos| of s_i, s_j).
  double ambiguity_correlation{0.95};
};

struct ParityGlrResult {
  bool detected{false};
  double statistic{0.0};            ///< largest l over instruments and onsets
  double threshold{0.0};            ///< h
  int instrument{-1};               ///< of the largest l
  double magnitude{0.0};            ///< b^ of that instrument at that onset [measurement units]
  double magnitude_sigma{0.0};      ///< its standard error, 1 / sqrt(R)
  int samples_since_onset{0};       ///< N(theta) of that onset
  int runner_up{-1};                ///< the instrument that explains the data about as well, or -1
  double runner_up_magnitude{0.0};  ///< b^ of runner_up at the same onset (eq. 11)
  bool ambiguous{false};            ///< runner_up cannot be told apart from instrument
};

class ParityGlr {
 public:
  /// nullopt with `error` naming the key and value when the configuration is out of range
  /// (onsets 1..kMaxOnsets, onset_spacing >= 1, probabilities in (0, 1)).
  static std::optional<ParityGlr> make(const ParitySpace& space, const ParityGlrConfig& config,
                                       std::string& error);
  static constexpr int kMaxOnsets = 200;

  /// One sample of every instrument (time-aligned, in the measurement units of the sigmas).
  const ParityGlrResult& update(const parity::Measurements& m);
  /// Forgets every onset (after a reconfiguration or a gap).
  void reset();

  const ParitySpace& space() const { return space_; }
  double threshold() const { return threshold_; }
  /// The bias of instrument j detected with the configured probability once it has lasted the
  /// whole window (onsets x onset_spacing samples), in the measurement units.
  double minimumDetectableBias(int j) const;
  int windowSamples() const { return config_.onsets * config_.onset_spacing; }
  const ParityGlrResult& last() const { return result_; }

 private:
  ParityGlr(const ParitySpace& space, const ParityGlrConfig& config);
  void evaluate();

  ParitySpace space_;
  ParityGlrConfig config_;
  double threshold_{0.0};
  double detectable_noncentrality_{0.0};
  /// s_j^T p summed from each onset on (column = ring position), and the samples since it.
  Eigen::Matrix<double, parity::kMaxInstruments, kMaxOnsets> f_{};
  std::array<int, kMaxOnsets> samples_{};
  Eigen::Matrix<double, parity::kMaxInstruments, 1> information_{};  ///< |s_j|^2
  int head_{0};         ///< ring position of the oldest onset
  int count_{0};        ///< onsets in the window
  int since_onset_{0};  ///< samples since the newest onset began
  ParityGlrResult result_;
};

}  // namespace navbus::core
