// Redundant GNSS receivers (receiver_consistency.hpp): the common-mode parity space of the
// single differences, a spoofed satellite isolated by the cross-receiver test and not by the
// other satellites, a receiver's clock jump named by its own clock test, and quiet fault-free
// epochs.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "navbus/core/integrity/parity_space.hpp"
#include "navbus/core/integrity/receiver_consistency.hpp"
#include "navbus/core/math/earth.hpp"

namespace nc = navbus::core;

namespace {

constexpr double kSigmaM = 3.0;  ///< pseudorange noise of both receivers [m]

/// Two receivers 1.5 m apart at 36.5 N 127.5 E, 1000 m, still; six satellites at 20,200 km
/// spread over the sky; pseudoranges with each receiver's clock (bias, drift) and noise.
class TwoReceivers {
 public:
  explicit TwoReceivers(unsigned seed) : rng_(seed) {
    const nc::earth::Geodetic p{36.5 * M_PI / 180.0, 127.5 * M_PI / 180.0, 1000.0};
    rx_[0] = nc::earth::geodeticToEcef(p);
    const Eigen::Matrix3d C_n_e = nc::earth::C_n_e(p.latitude_rad, p.longitude_rad);
    rx_[1] = rx_[0] + C_n_e * Eigen::Vector3d(-1.5, 0.0, -0.3);
    const double az[6] = {0.3, 1.4, 2.5, 3.6, 4.7, 5.8};
    const double el[6] = {0.9, 0.4, 1.2, 0.5, 0.3, 0.7};
    for (int k = 0; k < 6; ++k) {
      const Eigen::Vector3d los_n(std::cos(el[k]) * std::cos(az[k]),
                                  std::cos(el[k]) * std::sin(az[k]), -std::sin(el[k]));
      sats_[k] = rx_[0] + C_n_e * los_n * 2.02e7;
    }
  }
  /// Receiver r's epoch at t [s]; `extra_m` added to satellite `sv` (0: none).
  std::vector<nc::ReceiverSatellite> epoch(int r, double t, int sv = 0, double extra_m = 0.0) {
    std::normal_distribution<double> noise(0.0, kSigmaM);
    std::vector<nc::ReceiverSatellite> out;
    const double clock = (r == 0 ? 3000.0 : -12000.0) + (r == 0 ? 1.0 : -0.4) * t + jump_m_[r];
    for (int k = 0; k < 6; ++k) {
      nc::ReceiverSatellite s;
      s.sv_id = k + 1;
      s.range.sat_pos_ecef_m = sats_[k];
      s.range.sat_vel_ecef_mps.setZero();
      s.range.pseudorange_m =
          (sats_[k] - rx_[r]).norm() + clock + noise(rng_) + (s.sv_id == sv ? extra_m : 0.0);
      s.range.pseudorange_rate_mps = (r == 0 ? 1.0 : -0.4) + 0.05 * noise(rng_) / kSigmaM;
      s.pseudorange_sigma_m = kSigmaM;
      s.rate_sigma_mps = 0.05;
      out.push_back(s);
    }
    return out;
  }
  void jump(int r, double m) { jump_m_[r] += m; }

 private:
  std::mt19937_64 rng_;
  Eigen::Vector3d rx_[2];
  Eigen::Vector3d sats_[6];
  double jump_m_[2] = {0.0, 0.0};
};

nc::ParityGlrConfig glrConfig() {
  nc::ParityGlrConfig g;
  g.onsets = 5;
  g.onset_spacing = 1;
  g.false_alarm_probability = 1e-9;
  return g;
}

}  // namespace

TEST(ReceiverConsistency, TheCommonModeParityIsOrthogonalToTheClockAndWhite) {
  // Given five single differences of different sigmas, when their common-mode parity space is
  // built, then V W 1 = 0 (no clock difference reaches the parity), V W Sigma (V W)^T = I, the
  // estimate is the weighted mean, and fewer than two instruments are refused.
  nc::parity::Measurements sigmas(5);
  sigmas << 3, 4, 5, 3.5, 6;
  std::string error;
  const auto space = nc::ParitySpace::makeCommonMode(sigmas, error);
  ASSERT_TRUE(space) << error;
  EXPECT_EQ(space->dimension(), 4);
  const nc::parity::Matrix& vw = space->parityMatrix();
  EXPECT_LT((vw * nc::parity::Measurements::Ones(5)).norm(), 1e-12);
  const Eigen::MatrixXd cov = vw * sigmas.cwiseAbs2().asDiagonal() * vw.transpose();
  EXPECT_LT((cov - Eigen::MatrixXd::Identity(4, 4)).norm(), 1e-9);
  nc::parity::Measurements m(5);
  m << 10, 12, 9, 11, 8;
  const Eigen::ArrayXd w = sigmas.cwiseAbs2().cwiseInverse().array();
  EXPECT_NEAR(space->estimate(m)[0], (w * m.array()).sum() / w.sum(), 1e-9);
  EXPECT_FALSE(nc::ParitySpace::makeCommonMode(nc::parity::Measurements::Ones(1), error));
  EXPECT_NE(error.find("needs 2"), std::string::npos) << error;
}

TEST(ReceiverConsistency, ASpoofedSatelliteIsIsolatedAcrossReceiversAndQuietOtherwise) {
  // Given two receivers of six satellites (3 m noise, 1.5 m apart, clocks far apart and
  // drifting), when 600 fault-free epochs are tested, then nothing is detected; when satellite 4
  // of receiver 2 then reads 40 m long, then the test isolates satellite 4 within 5 epochs, its
  // difference (reference minus other) about -40 m.
  TwoReceivers rx(7);
  nc::ReceiverPairConsistency pair(glrConfig(), 1.53);
  for (int t = 0; t < 600; ++t) {
    const auto& r = pair.update(rx.epoch(0, t), rx.epoch(1, t));
    ASSERT_FALSE(r.glr.detected) << "false alarm at epoch " << t << ", l " << r.glr.statistic;
  }
  EXPECT_GT(pair.minimumDetectableDifference(), 5.0);
  EXPECT_LT(pair.minimumDetectableDifference(), 40.0);
  int detected_after = -1;
  for (int t = 600; t < 610 && detected_after < 0; ++t) {
    const auto& r = pair.update(rx.epoch(0, t), rx.epoch(1, t, 4, 40.0));
    if (!r.glr.detected) continue;
    detected_after = t - 600;
    EXPECT_EQ(r.sv_id, 4);
    EXPECT_NEAR(r.glr.magnitude, -40.0, 5.0 * r.glr.magnitude_sigma);
  }
  EXPECT_GE(detected_after, 0);
  EXPECT_LT(detected_after, 5);
}

TEST(ReceiverConsistency, AClockJumpIsNamedByThatReceiversOwnClockTest) {
  // Given each receiver's clock monitor over 300 fault-free epochs, then neither reports a jump;
  // when receiver 2's clock then steps by 1 ms, then its monitor reports a jump of 299,792 m
  // (to 30 m) at that epoch, and receiver 1's does not.
  TwoReceivers rx(11);
  nc::ReceiverClockConfig c;
  nc::ReceiverClockMonitor clock1(c), clock2(c);
  for (int t = 0; t < 300; ++t) {
    ASSERT_FALSE(clock1.update(t, rx.epoch(0, t))) << t;
    ASSERT_FALSE(clock2.update(t, rx.epoch(1, t))) << t;
  }
  EXPECT_LT(clock1.largestStatistic(), clock1.threshold());
  rx.jump(1, 1e-3 * nc::earth::kSpeedOfLight_mps);
  EXPECT_FALSE(clock1.update(300, rx.epoch(0, 300)));
  const auto jump = clock2.update(300, rx.epoch(1, 300));
  ASSERT_TRUE(jump);
  EXPECT_NEAR(jump->magnitude_m, 299792.458, 30.0);
  // The monitor follows the new clock: no second report.
  EXPECT_FALSE(clock2.update(301, rx.epoch(1, 301)));
}
