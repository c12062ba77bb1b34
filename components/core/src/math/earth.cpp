#include "navbus/core/math/earth.hpp"

#include <cmath>

#include <Eigen/Geometry>

namespace navbus::core::earth {

namespace {
/// The sines and cosines of a position's latitude (l) and longitude (o), for the functions that
/// need several of them: computed once, the same values as where each is used.
struct SinCos {
  double sl, cl, so, co;
};
SinCos sinCosOf(double latitude_rad, double longitude_rad) {
  return {std::sin(latitude_rad), std::cos(latitude_rad), std::sin(longitude_rad),
          std::cos(longitude_rad)};
}

Radii radiiFromSinLatitude(double s) {
  const double w2 = 1.0 - kEccentricitySq * s * s;
  const double w = std::sqrt(w2);
  return {kSemiMajorAxis_m * (1.0 - kEccentricitySq) / (w2 * w), kSemiMajorAxis_m / w};
}

Eigen::Vector3d ecefOf(const SinCos& t, double height_m) {
  const double n = radiiFromSinLatitude(t.sl).prime_vertical_m;
  return {(n + height_m) * t.cl * t.co, (n + height_m) * t.cl * t.so,
          (n * (1.0 - kEccentricitySq) + height_m) * t.sl};
}

/// Earth rate in NED from the sine and cosine of the latitude.
Eigen::Vector3d omegaIe(double sin_lat, double cos_lat) {
  return {kRotationRate_radps * cos_lat, 0.0, -kRotationRate_radps * sin_lat};
}

/// Transport rate in NED from the velocity, the radii, the height and tan(latitude).
Eigen::Vector3d omegaEn(const Eigen::Vector3d& v, const Radii& r, double height_m, double tan_lat) {
  const double rn = r.prime_vertical_m + height_m;
  const double rm = r.meridian_m + height_m;
  return {v.y() / rn, -v.x() / rm, -v.y() * tan_lat / rn};
}

Eigen::Matrix3d nedToEcef(const SinCos& t) {
  Eigen::Matrix3d c;
  // Columns are the N, E, D unit vectors expressed in ECEF.
  c << -t.sl * t.co, -t.so, -t.cl * t.co,  //
      -t.sl * t.so, t.co, -t.cl * t.so,    //
      t.cl, 0.0, -t.sl;
  return c;
}
}  // namespace

Radii radiiOfCurvature(double latitude_rad) {
  return radiiFromSinLatitude(std::sin(latitude_rad));
}

namespace {
/// Normal gravity from the sine of the latitude (normalGravity()).
double normalGravityFromSin(double sin_lat, double height_m) {
  const double s2 = std::pow(sin_lat, 2);
  // Somigliana closed formula, TR8350.2 eq. 4-1.
  const double k =
      (kSemiMinorAxis_m * kGravityPole_mps2) / (kSemiMajorAxis_m * kGravityEquator_mps2) - 1.0;
  const double g0 = kGravityEquator_mps2 * (1.0 + k * s2) / std::sqrt(1.0 - kEccentricitySq * s2);
  // Second-order height correction, TR8350.2 eq. 4-3, with m = w^2 a^2 b / GM.
  const double m = kRotationRate_radps * kRotationRate_radps * kSemiMajorAxis_m * kSemiMajorAxis_m *
                   kSemiMinorAxis_m / kGm_m3ps2;
  const double a = kSemiMajorAxis_m;
  return g0 * (1.0 - 2.0 / a * (1.0 + kFlattening + m - 2.0 * kFlattening * s2) * height_m +
               3.0 / (a * a) * height_m * height_m);
}
}  // namespace

double normalGravity(double latitude_rad, double height_m) {
  return normalGravityFromSin(std::sin(latitude_rad), height_m);
}

Eigen::Vector3d gravityNed(double latitude_rad, double height_m) {
  return {0.0, 0.0, normalGravity(latitude_rad, height_m)};
}

Eigen::Vector3d pointMassGravitationEcef(const Eigen::Vector3d& r) {
  const double n = r.norm();
  return -kGm_m3ps2 / (n * n * n) * r;
}

namespace {
/// Gravity in NED with the position's sines and cosines already computed.
Eigen::Vector3d gravityNed(GravityModel model, const SinCos& t, double height_m) {
  if (model == GravityModel::kWgs84Normal) return {0.0, 0.0, normalGravityFromSin(t.sl, height_m)};
  const Eigen::Vector3d r = ecefOf(t, height_m);
  const Eigen::Vector3d w(0.0, 0.0, kRotationRate_radps);
  const Eigen::Vector3d g_e = pointMassGravitationEcef(r) - w.cross(w.cross(r));
  return nedToEcef(t).transpose() * g_e;
}
}  // namespace

Eigen::Vector3d gravityNed(GravityModel model, const Geodetic& position) {
  if (model == GravityModel::kWgs84Normal) {
    return gravityNed(position.latitude_rad, position.height_m);
  }
  return gravityNed(model, sinCosOf(position.latitude_rad, position.longitude_rad),
                    position.height_m);
}

Geodetic offsetNed(const Geodetic& p, const Eigen::Vector3d& d) {
  const Radii r = radiiOfCurvature(p.latitude_rad);
  Geodetic out = p;
  out.latitude_rad += d.x() / (r.meridian_m + p.height_m);
  out.longitude_rad += d.y() / ((r.prime_vertical_m + p.height_m) * std::cos(p.latitude_rad));
  out.height_m -= d.z();
  return out;
}

Eigen::Vector3d differenceNed(const Geodetic& a, const Geodetic& b) {
  const Radii r = radiiOfCurvature(a.latitude_rad);
  return {(a.latitude_rad - b.latitude_rad) * (r.meridian_m + a.height_m),
          std::remainder(a.longitude_rad - b.longitude_rad, 2.0 * M_PI) *
              (r.prime_vertical_m + a.height_m) * std::cos(a.latitude_rad),
          -(a.height_m - b.height_m)};
}

Eigen::Vector3d geodeticToEcef(const Geodetic& p) {
  return ecefOf(sinCosOf(p.latitude_rad, p.longitude_rad), p.height_m);
}

Geodetic ecefToGeodetic(const Eigen::Vector3d& r) {
  Geodetic g;
  g.longitude_rad = std::atan2(r.y(), r.x());
  const double p = std::hypot(r.x(), r.y());
  // Fixed-point iteration on latitude; converges to 1e-15 rad in a few steps for |h| << a.
  double lat = std::atan2(r.z(), p * (1.0 - kEccentricitySq));
  double h = 0.0;
  for (int i = 0; i < 10; ++i) {
    const double n = radiiOfCurvature(lat).prime_vertical_m;
    const double sl = std::sin(lat);
    const double cl = std::cos(lat);
    // Height from the larger of the two projections keeps precision near the poles.
    h = (std::abs(cl) > 0.5) ? p / cl - n : r.z() / sl - n * (1.0 - kEccentricitySq);
    const double lat_next = std::atan2(r.z(), p * (1.0 - kEccentricitySq * n / (n + h)));
    if (std::abs(lat_next - lat) < 1e-15) {
      lat = lat_next;
      break;
    }
    lat = lat_next;
  }
  g.latitude_rad = lat;
  const double n = radiiOfCurvature(lat).prime_vertical_m;
  const double sl = std::sin(lat);
  const double cl = std::cos(lat);
  g.height_m = (std::abs(cl) > 0.5) ? p / cl - n : r.z() / sl - n * (1.0 - kEccentricitySq);
  return g;
}

Eigen::Matrix3d C_n_e(double latitude_rad, double longitude_rad) {
  return nedToEcef(sinCosOf(latitude_rad, longitude_rad));
}

Eigen::Vector3d omegaIeNed(double latitude_rad) {
  return omegaIe(std::sin(latitude_rad), std::cos(latitude_rad));
}

Eigen::Vector3d omegaEnNed(const Geodetic& p, const Eigen::Vector3d& v) {
  return omegaEnNed(p, v, radiiOfCurvature(p.latitude_rad));
}

Eigen::Vector3d omegaEnNed(const Geodetic& p, const Eigen::Vector3d& v, const Radii& r) {
  return omegaEn(v, r, p.height_m, std::tan(p.latitude_rad));
}

LocalEarth localEarth(GravityModel model, const Geodetic& p, const Eigen::Vector3d& v) {
  // One sine and cosine of each angle for the radii, the rates and the gravity.
  const SinCos t = sinCosOf(p.latitude_rad, p.longitude_rad);
  LocalEarth e;
  e.radii = radiiFromSinLatitude(t.sl);
  e.w_ie_ned = omegaIe(t.sl, t.cl);
  e.w_en_ned = omegaEn(v, e.radii, p.height_m, t.sl / t.cl);
  e.g_ned = gravityNed(model, t, p.height_m);
  return e;
}

Eigen::Matrix3d C_i_e(double gps_time_s) {
  const double a = kRotationRate_radps * gps_time_s;
  const double c = std::cos(a);
  const double s = std::sin(a);
  Eigen::Matrix3d m;
  m << c, s, 0.0,  //
      -s, c, 0.0,  //
      0.0, 0.0, 1.0;
  return m;
}

}  // namespace navbus::core::earth
