// Initial alignment from the inputs on the bus (see the header for the order of sources).
#include "navbus/core/engine/initial_alignment.hpp"

#include <algorithm>
#include <cmath>

#include "navbus/core/gnss/gnss_fix.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/core/math/rotation.hpp"

namespace navbus::core {

namespace {

/// Root mean square of the selected sigmas (the equal-weight least squares' measurement sigma).
template <typename Get>
double rmsSigma(const std::vector<SatelliteObservation>& sats, Get get) {
  double sum = 0.0;
  int n = 0;
  for (const auto& s : sats) {
    if (!s.use_range) continue;
    sum += get(s) * get(s);
    ++n;
  }
  return n > 0 ? std::sqrt(sum / n) : 0.0;
}

}  // namespace

InitialAligner::InitialAligner(const InitialAlignmentConfig& config) : config_(config) {
  rest_.configure(config_.rest, config_.imu_period_s);
}

void InitialAligner::addImu(const ImuIncrement& inc) {
  if (aligned()) return;
  last_imu_ns_ = inc.time_ns;
  if (phase_ == AlignmentPhase::kWaitingForCourse) propagateAttitude(inc);
  // The GNSS speed beyond 3 of its own sigmas: at rest it is noise of that size, which alone
  // must not break a rest window.
  const double speed_mps =
      hasFix() ? std::max(0.0, fix_.measurement.vel_ned_mps.head<2>().norm() -
                                   3.0 * fix_.measurement.vel_sigma_ned_mps.head<2>().maxCoeff())
               : 0.0;
  rest_.update(inc, speed_mps);
  if (!(rest_.ready() && rest_.stationary())) {
    onMotion();
    return;
  }
  newest_.add(inc);
  if (newest_.duration_s() < config_.rest.window_s) return;
  window_.add(recent_);  // one detector window older than the newest block: at rest for certain
  recent_ = newest_;
  newest_.reset();
  if (phase_ == AlignmentPhase::kWaitingForCourse) {
    relevel();
  } else if (window_.duration_s() >= config_.static_window_s && hasFix()) {
    onRestWindowEnd();
  }
}

void InitialAligner::onMotion() {
  // The detector sees motion up to one of its windows late, so the last two blocks may hold
  // some: they are dropped; what is older is used if long enough.
  recent_.reset();
  newest_.reset();
  if (phase_ != AlignmentPhase::kWaitingForCourse && hasFix() &&
      window_.duration_s() >= config_.min_static_window_s) {
    onRestWindowEnd();
  }
  window_.reset();
}

PseudorangeFix pseudorangeFix(std::int64_t time_ns, const std::vector<SatelliteObservation>& sats,
                              const Eigen::Vector3d& guess_ecef_m) {
  std::vector<RangeObservation> obs;
  obs.reserve(sats.size());
  for (const auto& s : sats) {
    if (!s.use_range) continue;
    obs.push_back({s.sat_pos_ecef_m, s.sat_vel_ecef_mps, s.pseudorange_m, s.pseudorange_rate_mps});
  }
  const LeastSquaresFix ls = leastSquaresFix(obs, guess_ecef_m);
  PseudorangeFix f;
  if (!ls.valid) return f;
  // Equal-weight least squares: each estimate's sigma is its DOP times the measurement sigma.
  // Each horizontal axis gets the whole HDOP (an upper bound: the split is not known).
  const double range_sigma_m = rmsSigma(sats, [](const auto& s) { return s.pseudorange_sigma_m; });
  const double rate_sigma_mps =
      rmsSigma(sats, [](const auto& s) { return s.pseudorange_rate_sigma_mps; });
  f.valid = true;
  f.fix.time_ns = time_ns;
  f.fix.position = earth::ecefToGeodetic(ls.pos_ecef_m);
  const Eigen::Matrix3d C_n_e =
      earth::C_n_e(f.fix.position.latitude_rad, f.fix.position.longitude_rad);
  f.fix.vel_ned_mps = C_n_e.transpose() * ls.vel_ecef_mps;
  f.fix.pos_sigma_ned_m = Eigen::Vector3d(ls.hdop, ls.hdop, ls.vdop) * range_sigma_m;
  f.fix.vel_sigma_ned_mps = Eigen::Vector3d(ls.hdop, ls.hdop, ls.vdop) * rate_sigma_mps;
  f.clock_bias_m = ls.clock_bias_m;
  f.clock_drift_mps = ls.clock_drift_mps;
  f.clock_bias_sigma_m = ls.tdop * range_sigma_m;
  f.clock_drift_sigma_mps = ls.tdop * rate_sigma_mps;
  return f;
}

void InitialAligner::addPseudoranges(std::int64_t time_ns,
                                     const std::vector<SatelliteObservation>& sats) {
  if (aligned()) return;
  const Eigen::Vector3d guess_ecef =
      hasFix() ? earth::geodeticToEcef(fix_.measurement.position) : Eigen::Vector3d::Zero();
  const PseudorangeFix pf = pseudorangeFix(time_ns, sats, guess_ecef);
  if (!pf.valid) {
    ++failed_solutions_;
    return;
  }
  Fix f;
  f.time_ns = time_ns;
  f.source = PositionSource::kPseudoranges;
  f.measurement = pf.fix;
  f.clock_bias_m = pf.clock_bias_m;
  f.clock_drift_mps = pf.clock_drift_mps;
  f.clock_bias_sigma_m = pf.clock_bias_sigma_m;
  f.clock_drift_sigma_mps = pf.clock_drift_sigma_mps;
  takeFix(f);
}

void InitialAligner::addGnssFix(const GnssFixMeasurement& fix) {
  if (aligned()) return;
  Fix f;
  f.time_ns = fix.time_ns;
  f.source = PositionSource::kGnssFix;
  f.measurement = fix;
  takeFix(f);
}

void InitialAligner::addStarAttitude(const StarAttitudeMeasurement& st) {
  // Expressed in NED at the fix position; before the first fix and increment it waits for the
  // next sample.
  if (aligned() || !hasFix() || last_imu_ns_ < 0) return;
  const earth::Geodetic& p = fix_.measurement.position;
  const Eigen::Matrix3d C_b_n = earth::C_n_e(p.latitude_rad, p.longitude_rad).transpose() *
                                earth::C_i_e(1e-9 * static_cast<double>(st.time_ns)) *
                                st.q_b_to_i.normalized().toRotationMatrix();
  // Body-axis error sigmas seen about the NED axes: the diagonal of C Sigma_b C^T.
  const Eigen::Matrix3d cov_n = C_b_n * st.sigma_b_rad.cwiseAbs2().asDiagonal() * C_b_n.transpose();
  finish(Eigen::Quaterniond(C_b_n).normalized(), cov_n.diagonal().cwiseSqrt(),
         AttitudeSource::kStarTracker);
}

void InitialAligner::takeFix(const Fix& fix) {
  fix_ = fix;
  if (phase_ == AlignmentPhase::kWaitingForPosition) phase_ = AlignmentPhase::kWaitingForRest;
  if (phase_ != AlignmentPhase::kWaitingForCourse) return;
  const GnssFixMeasurement& m = fix.measurement;
  track_[track_next_] = {fix.time_ns, m.position, m.pos_sigma_ned_m.head<2>().maxCoeff(),
                         eulerFromDcm(q_levelled_b_to_n_.toRotationMatrix()).z(),
                         levelled_dv_ne_mps_};
  track_next_ = (track_next_ + 1) % kTrackPoints;
  track_count_ = std::min(track_count_ + 1, kTrackPoints);
  tryCourse();
}

void InitialAligner::onRestWindowEnd() {
  const CoarseAlignment coarse = alignWindow(config_.max_heading_sigma_rad);
  gyrocompass_sigma_rad_ = coarse.heading_sigma_rad;
  if (coarse.hasHeading()) {
    finish(
        coarse.q_b_to_n,
        Eigen::Vector3d(coarse.level_sigma_rad, coarse.level_sigma_rad, coarse.heading_sigma_rad),
        AttitudeSource::kGyrocompass,
        alignmentSensitivity(coarse.q_b_to_n.toRotationMatrix(),
                             fix_.measurement.position.latitude_rad, gravity(), true));
    return;
  }
  q_levelled_b_to_n_ = coarse.q_b_to_n;
  q_at_levelling_b_to_n_ = q_levelled_b_to_n_;
  level_sigma_rad_ = coarse.level_sigma_rad;
  levelled_for_s_ = 0.0;
  phase_ = AlignmentPhase::kWaitingForCourse;
  tryCourse();
}

double InitialAligner::gravity() const {
  const earth::Geodetic& p = fix_.measurement.position;
  return earth::normalGravity(p.latitude_rad, p.height_m);
}

CoarseAlignment InitialAligner::alignWindow(double max_heading_sigma_rad) const {
  return alignStatic(window_, fix_.measurement.position.latitude_rad, gravity(), config_.budget,
                     max_heading_sigma_rad);
}

void InitialAligner::relevel() {
  // Still at rest while waiting for the course: roll and pitch again from the whole rest
  // window, the heading carried by the gyros kept, when that window is at least
  // min_static_window_s long and levels better than the last levelling carried since. A short
  // "rest" while waiting for the course is often none: steady acceleration or turning has no
  // scatter either, and a position-only receiver's speed cannot tell (seed 004 with positions
  // only: 1-s windows of a car accelerating at 2 m/s^2 tilted the start by 0.2 rad). And the
  // first block of a new rest has no window at all (an infinite sigma).
  if (window_.duration_s() < config_.min_static_window_s) return;
  const CoarseAlignment coarse = alignWindow(0.0);
  if (!(coarse.level_sigma_rad < currentLevelSigma())) return;
  const double yaw_rad = eulerFromDcm(q_levelled_b_to_n_.toRotationMatrix()).z();
  q_levelled_b_to_n_ =
      Eigen::Quaterniond(dcmFromEuler(Eigen::Vector3d(coarse.roll_pitch_yaw_rad.x(),
                                                      coarse.roll_pitch_yaw_rad.y(), yaw_rad)))
          .normalized();
  q_at_levelling_b_to_n_ = q_levelled_b_to_n_;
  level_sigma_rad_ = coarse.level_sigma_rad;
  levelled_for_s_ = 0.0;
}

double InitialAligner::currentLevelSigma() const {
  // The last levelling, then the gyro bias and the unmodelled horizontal Earth rate integrated
  // since (propagateAttitude).
  const double horizontal_earth_rate_radps =
      earth::kRotationRate_radps * std::cos(fix_.measurement.position.latitude_rad);
  const double tilt_rate_radps =
      std::hypot(config_.budget.gyro_bias_sigma_radps, horizontal_earth_rate_radps);
  return std::hypot(level_sigma_rad_, tilt_rate_radps * levelled_for_s_);
}

void InitialAligner::propagateAttitude(const ImuIncrement& inc) {
  // Body rotation, then the navigation frame's rotation with the Earth about the vertical only:
  // the horizontal Earth rate's direction in the body needs the heading, which is unknown (and
  // below what this gyro grade resolves, or gyrocompassing would have given the heading). The
  // transport rate is left out too (below 1e-6 rad/s at the speeds before the course is taken).
  // Both go into the tilt sigma (tryCourse).
  const double latitude_rad = fix_.measurement.position.latitude_rad;
  const Eigen::Vector3d earth_rotation_n(
      0.0, 0.0, -earth::kRotationRate_radps * std::sin(latitude_rad) * inc.interval_s);
  q_levelled_b_to_n_ = quaternionFromRotationVector(-earth_rotation_n) * q_levelled_b_to_n_ *
                       quaternionFromRotationVector(inc.delta_angle_b_rad);
  q_levelled_b_to_n_.normalize();
  // Gravity has no horizontal component: the horizontal specific force is the acceleration.
  levelled_dv_ne_mps_ += (q_levelled_b_to_n_ * inc.delta_vel_b_mps).head<2>();
  levelled_for_s_ += inc.interval_s;
}

std::optional<InitialAligner::Course> InitialAligner::courseFromVelocity() const {
  const Eigen::Vector3d& v = fix_.measurement.vel_ned_mps;
  const double speed_mps = v.head<2>().norm();
  if (speed_mps < config_.course_min_speed_mps) return std::nullopt;
  // The body-to-velocity misalignment and the velocity's own noise across the track.
  const double cross_track_sigma_mps = fix_.measurement.vel_sigma_ned_mps.head<2>().maxCoeff();
  return Course{std::atan2(v.y(), v.x()), eulerFromDcm(q_levelled_b_to_n_.toRotationMatrix()).z(),
                std::hypot(config_.course_sigma_rad, cross_track_sigma_mps / speed_mps),
                std::nullopt};
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> InitialAligner::chordVelocity(
    const TrackPoint& now, const TrackPoint& then, double heading_correction_rad) const {
  // The chord gives the mean velocity, the one at mid-interval for a steady acceleration; the
  // velocity at the newer fix adds half the change the accelerometers integrated since (in the
  // levelled frame, turned by the heading found). Its sigma: the fixes' over the interval, and
  // the levelling's tilt leaking gravity into the integral.
  const double dt_s = 1e-9 * static_cast<double>(now.time_ns - then.time_ns);
  const Eigen::Vector3d chord_ned = earth::differenceNed(now.position, then.position);
  const Eigen::Rotation2Dd turn(heading_correction_rad);
  Eigen::Vector3d v = chord_ned / dt_s;
  v.head<2>() += turn * (0.5 * (now.levelled_dv_ne_mps - then.levelled_dv_ne_mps));
  const double horizontal_sigma = std::hypot(std::hypot(now.sigma_h_m, then.sigma_h_m) / dt_s,
                                             0.5 * level_sigma_rad_ * gravity() * dt_s);
  const double vertical_sigma =
      std::hypot(fix_.measurement.pos_sigma_ned_m.z() * std::sqrt(2.0) / dt_s,
                 0.5 * level_sigma_rad_ * gravity() * dt_s);
  return {v, Eigen::Vector3d(horizontal_sigma, horizontal_sigma, vertical_sigma)};
}

std::optional<InitialAligner::Course> InitialAligner::courseFromPositions() const {
  if (track_count_ < 2) return std::nullopt;
  const TrackPoint& now = track_[(track_next_ + kTrackPoints - 1) % kTrackPoints];
  std::optional<Course> best;
  for (std::size_t k = 1; k < track_count_; ++k) {
    const TrackPoint& then = track_[(track_next_ + kTrackPoints - 1 - k) % kTrackPoints];
    const double dt_s = 1e-9 * static_cast<double>(now.time_ns - then.time_ns);
    if (!(dt_s > 0.0) || dt_s > config_.course_window_s) break;
    // The chord is the course only where the track is straight: the gyros' turn between.
    const double turn_rad = std::remainder(now.yaw_rad - then.yaw_rad, 2.0 * M_PI);
    if (std::abs(turn_rad) > 2.0 * config_.course_sigma_rad) continue;
    const Eigen::Vector3d chord_ned = earth::differenceNed(now.position, then.position);
    const double length_m = chord_ned.head<2>().norm();
    if (length_m < config_.course_min_speed_mps * dt_s) continue;
    const double sigma_rad =
        std::hypot(config_.course_sigma_rad, std::hypot(now.sigma_h_m, then.sigma_h_m) / length_m);
    if (best && sigma_rad >= best->heading_sigma_rad) continue;
    const double course_rad = std::atan2(chord_ned.y(), chord_ned.x());
    const double yaw_rad = then.yaw_rad + 0.5 * turn_rad;
    best = Course{course_rad, yaw_rad, sigma_rad, chordVelocity(now, then, course_rad - yaw_rad)};
  }
  return best;
}

void InitialAligner::tryCourse() {
  // The better of the fix's velocity and the chord between two fixes; none while the heading
  // would not be known well enough for the filter's error model.
  std::optional<Course> c = courseFromVelocity();
  if (const std::optional<Course> p = courseFromPositions();
      p && (!c || p->heading_sigma_rad < c->heading_sigma_rad))
    c = p;
  if (!c || c->heading_sigma_rad > config_.max_course_heading_sigma_rad) return;
  const double course_rad = c->course_rad;
  const double yaw_rad = c->yaw_rad;
  const Eigen::Quaterniond q =
      Eigen::Quaterniond(Eigen::AngleAxisd(course_rad - yaw_rad, Eigen::Vector3d::UnitZ())) *
      q_levelled_b_to_n_;
  const double heading_sigma_rad = c->heading_sigma_rad;
  // Tilt: the last levelling, then the gyro bias and the unmodelled horizontal Earth rate
  // integrated since (propagateAttitude).
  const double level_sigma_rad = currentLevelSigma();
  // The tilt errors are those of the latest levelling, whose attitude is now known with the
  // course's heading correction (step 8, levelling rows only).
  const Eigen::Matrix3d C_at_levelling =
      Eigen::AngleAxisd(course_rad - yaw_rad, Eigen::Vector3d::UnitZ()) *
      q_at_levelling_b_to_n_.toRotationMatrix();
  // The gyro bias integrated since the levelling tilts the attitude too: d(phi)/dt = C_b_n e_g
  // with the bias error e_g = -b (the estimate starts at 0), so phi_tilt gains -C_b_n b dt and
  // the tilt rows of d(phi)/d(b) gain -C_b_n dt (the heading came from the course since).
  AlignmentSensitivity sensitivity = alignmentSensitivity(
      C_at_levelling, fix_.measurement.position.latitude_rad, gravity(), false);
  sensitivity.d_att_d_gyro_bias_b.topRows<2>() =
      -q.toRotationMatrix().topRows<2>() * levelled_for_s_;
  if (c->velocity_ned_mps && c->velocity_ned_mps->second.head<2>().maxCoeff() <
                                 fix_.measurement.vel_sigma_ned_mps.head<2>().maxCoeff()) {
    // The fix's own velocity is worse (a position-only receiver): the chord's.
    fix_.measurement.vel_ned_mps = c->velocity_ned_mps->first;
    fix_.measurement.vel_sigma_ned_mps = c->velocity_ned_mps->second;
  }
  finish(q.normalized(), Eigen::Vector3d(level_sigma_rad, level_sigma_rad, heading_sigma_rad),
         AttitudeSource::kGnssCourse, sensitivity);
}

void InitialAligner::finish(const Eigen::Quaterniond& q_b_to_n,
                            const Eigen::Vector3d& att_sigma_ned_rad, AttitudeSource source,
                            const AlignmentSensitivity& sensitivity) {
  // The fix is carried to the time of the last increment with its velocity.
  const double dt_s = 1e-9 * static_cast<double>(last_imu_ns_ - fix_.time_ns);
  const GnssFixMeasurement& m = fix_.measurement;
  start_.state.time_ns = last_imu_ns_;
  start_.state.position = earth::offsetNed(m.position, m.vel_ned_mps * dt_s);
  start_.state.vel_ned_mps = m.vel_ned_mps;
  start_.state.q_b_to_n = q_b_to_n;
  start_.pos_sigma_ned_m =
      (m.pos_sigma_ned_m.cwiseAbs2() + (m.vel_sigma_ned_mps * dt_s).cwiseAbs2()).cwiseSqrt();
  start_.vel_sigma_ned_mps = m.vel_sigma_ned_mps;
  start_.att_sigma_ned_rad = att_sigma_ned_rad;
  start_.has_clock = fix_.source == PositionSource::kPseudoranges;
  start_.clock_bias_m = fix_.clock_bias_m + fix_.clock_drift_mps * dt_s;
  start_.clock_drift_mps = fix_.clock_drift_mps;
  start_.clock_bias_sigma_m =
      std::hypot(fix_.clock_bias_sigma_m, fix_.clock_drift_sigma_mps * dt_s);
  start_.clock_drift_sigma_mps = fix_.clock_drift_sigma_mps;
  start_.attitude_source = source;
  start_.position_source = fix_.source;
  start_.gyrocompass_heading_sigma_rad = gyrocompass_sigma_rad_;
  start_.sensitivity = sensitivity;
  phase_ = AlignmentPhase::kAligned;
}

}  // namespace navbus::core
