// Unit constants: configuration files use the units of the papers' tables; everything inside
// is SI. Multiply a value in the named unit by the constant to get SI.
#pragma once

#include <cmath>

namespace navbus::units {

inline constexpr double kStandardGravity = 9.80665;         ///< [m/s^2] per g
inline constexpr double kMilliG = 1e-3 * kStandardGravity;  ///< [m/s^2] per mg
inline constexpr double kMicroG = 1e-6 * kStandardGravity;  ///< [m/s^2] per ug
inline constexpr double kDeg = M_PI / 180.0;                ///< [rad] per degree
inline constexpr double kArcsec = kDeg / 3600.0;            ///< [rad] per arcsecond
inline constexpr double kDegPerHour = kDeg / 3600.0;        ///< [rad/s] per deg/h
inline constexpr double kPpm = 1e-6;                        ///< [1] per part per million

}  // namespace navbus::units
