#include "navbus/core/ins/imu_array_combination.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace navbus::core {

namespace {

/// Smallest eigenvalue of H^T W^2 H over its largest: below it the instruments are taken as not
/// spanning three axes.
constexpr double kSpanTolerance = 1e-9;

std::size_t kindIndex(ImuInstrument kind) {
  return static_cast<std::size_t>(kind);
}

}  // namespace

std::optional<ImuArrayCombination> ImuArrayCombination::make(const std::vector<ImuArrayUnit>& units,
                                                             double interval_s,
                                                             std::string& error) {
  if (!checkImuArray(units, interval_s, kMaxUnits, error)) return std::nullopt;
  return ImuArrayCombination(units, interval_s);
}

ImuArrayCombination::ImuArrayCombination(std::vector<ImuArrayUnit> units, double interval_s)
    : units_(std::move(units)), interval_s_(interval_s) {
  const std::uint32_t all = (1u << (3 * units_.size())) - 1u;
  included_.fill(all);
  cacheEstimators();
}

void ImuArrayCombination::cacheEstimators() {
  for (int k = 0; k < kImuInstrumentKinds; ++k) {
    Cached& c = all_present_[static_cast<std::size_t>(k)];
    estimator(static_cast<ImuInstrument>(k), allUnits(), c.e, c.rows, c.n);
  }
}

bool ImuArrayCombination::included(ImuInstrument kind, int unit, int axis) const {
  if (unit < 0 || unit >= units() || axis < 0 || axis > 2) return false;
  return (included_[kindIndex(kind)] >> (3 * unit + axis)) & 1u;
}

bool ImuArrayCombination::exclude(ImuInstrument kind, int unit, int axis) {
  if (!included(kind, unit, axis)) return false;
  std::uint32_t& mask = included_[kindIndex(kind)];
  const std::uint32_t before = mask;
  mask &= ~(1u << (3 * unit + axis));
  Estimator e;
  std::array<int, kMaxInstruments> rows{};
  int n = 0;
  if (!estimator(kind, allUnits(), e, rows, n)) {
    mask = before;  // the rest would not span three axes: the instrument stays
    return false;
  }
  ++generation_;
  cacheEstimators();
  return true;
}

bool ImuArrayCombination::excludeUnit(int unit) {
  if (unit < 0 || unit >= units()) return false;
  const std::array<std::uint32_t, kImuInstrumentKinds> before = included_;
  bool changed = false;
  for (std::uint32_t& mask : included_) {
    changed = changed || (mask & (7u << (3 * unit))) != 0;
    mask &= ~(7u << (3 * unit));
  }
  Estimator e;
  std::array<int, kMaxInstruments> rows{};
  int n = 0;
  if (!changed || !estimator(ImuInstrument::kGyro, allUnits(), e, rows, n) ||
      !estimator(ImuInstrument::kAccelerometer, allUnits(), e, rows, n)) {
    included_ = before;
    return false;
  }
  ++generation_;
  cacheEstimators();
  return true;
}

bool ImuArrayCombination::estimator(ImuInstrument kind, std::uint32_t present, Estimator& e,
                                    std::array<int, kMaxInstruments>& rows, int& n,
                                    Eigen::Matrix3d* covariance) const {
  using Axes = Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxInstruments, 3>;
  Axes wh(3 * units(), 3);  // W H, row per included instrument of a present unit (eq. 1)
  n = 0;
  for (int u = 0; u < units(); ++u) {
    if (((present >> u) & 1u) == 0) continue;
    const ImuArrayUnit& unit = units_[static_cast<std::size_t>(u)];
    const double sigma = kind == ImuInstrument::kGyro ? unit.gyro_sigma_rad : unit.accel_sigma_mps;
    for (int a = 0; a < 3; ++a) {
      if (!included(kind, u, a)) continue;
      wh.row(n) = unit.c_u_b.row(a) / sigma;
      rows[static_cast<std::size_t>(n++)] = 3 * u + a;
    }
  }
  if (n < 3) return false;
  const Eigen::Matrix3d information = wh.topRows(n).transpose() * wh.topRows(n);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(information, Eigen::EigenvaluesOnly);
  if (!(eig.eigenvalues()[0] > kSpanTolerance * eig.eigenvalues()[2])) return false;
  const Eigen::Matrix3d cov = information.ldlt().solve(Eigen::Matrix3d::Identity());
  e.resize(3, n);
  // E = (H^T W^2 H)^-1 H^T W^2 = cov (W H)^T W.
  for (int r = 0; r < n; ++r) {
    const int i = rows[static_cast<std::size_t>(r)];
    const ImuArrayUnit& unit = units_[static_cast<std::size_t>(i / 3)];
    const double sigma = kind == ImuInstrument::kGyro ? unit.gyro_sigma_rad : unit.accel_sigma_mps;
    e.col(r) = cov * wh.row(r).transpose() / sigma;
  }
  if (covariance != nullptr) *covariance = cov;
  return true;
}

std::optional<Eigen::Vector3d> ImuArrayCombination::solve(
    ImuInstrument kind, std::uint32_t present,
    const std::array<Eigen::Vector3d, kMaxUnits>& m) const {
  Cached own;
  const Cached* c = &all_present_[kindIndex(kind)];
  if (present != allUnits()) {
    if (!estimator(kind, present, own.e, own.rows, own.n)) return std::nullopt;
    c = &own;
  }
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  for (int r = 0; r < c->n; ++r) {
    const int i = c->rows[static_cast<std::size_t>(r)];
    x += c->e.col(r) * m[static_cast<std::size_t>(i / 3)][i % 3];
  }
  return x;
}

std::optional<ImuIncrement> ImuArrayCombination::combine(
    const std::array<ImuIncrement, kMaxUnits>& increments, std::uint32_t present) {
  present &= allUnits();
  if (present == 0) return std::nullopt;
  std::array<Eigen::Vector3d, kMaxUnits> m{};
  for (int u = 0; u < units(); ++u)
    m[static_cast<std::size_t>(u)] = increments[static_cast<std::size_t>(u)].delta_angle_b_rad;
  const std::optional<Eigen::Vector3d> dtheta = solve(ImuInstrument::kGyro, present, m);
  if (!dtheta) return std::nullopt;
  // The lever-arm term of each accelerometer (imu_array.hpp), first order: w the combined rate,
  // dw/dt from the previous sample's.
  const Eigen::Vector3d w = *dtheta / interval_s_;
  const Eigen::Vector3d w_dot = have_previous_rate_
                                    ? Eigen::Vector3d((w - previous_rate_b_radps_) / interval_s_)
                                    : Eigen::Vector3d::Zero();
  previous_rate_b_radps_ = w;
  have_previous_rate_ = true;
  for (int u = 0; u < units(); ++u) {
    const ImuArrayUnit& unit = units_[static_cast<std::size_t>(u)];
    m[static_cast<std::size_t>(u)] =
        increments[static_cast<std::size_t>(u)].delta_vel_b_mps -
        unit.c_u_b * leverArmSpecificForce(w, w_dot, unit.lever_arm_b_m) * interval_s_;
  }
  const std::optional<Eigen::Vector3d> dv = solve(ImuInstrument::kAccelerometer, present, m);
  if (!dv) return std::nullopt;
  int first = 0;
  while (((present >> first) & 1u) == 0) ++first;
  ImuIncrement out;
  out.time_ns = increments[static_cast<std::size_t>(first)].time_ns;
  out.interval_s = increments[static_cast<std::size_t>(first)].interval_s;
  out.delta_angle_b_rad = *dtheta;
  out.delta_vel_b_mps = *dv;
  return out;
}

Eigen::Vector3d ImuArrayCombination::sigma(ImuInstrument kind) const {
  Estimator e;
  std::array<int, kMaxInstruments> rows{};
  int n = 0;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  estimator(kind, allUnits(), e, rows, n, &cov);  // exclude() keeps the included set spanning
  return cov.diagonal().cwiseSqrt();
}

Eigen::Vector3d ImuArrayCombination::combinedBias(
    ImuInstrument kind, const std::array<Eigen::Vector3d, kMaxUnits>& bias_u) const {
  return solve(kind, allUnits(), bias_u).value_or(Eigen::Vector3d::Zero());
}

}  // namespace navbus::core
