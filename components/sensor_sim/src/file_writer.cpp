#include "navbus/sensor_sim/file_writer.hpp"

#include <cstdio>
#include <stdexcept>

#include "navbus/core/math/earth.hpp"
#include "navbus/core/math/rotation.hpp"

namespace navbus::sensor_sim {

namespace {
/// 17 significant digits: the files read back to the same doubles.
std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}
std::string vec(const Eigen::Vector3d& v) {
  return num(v.x()) + "," + num(v.y()) + "," + num(v.z());
}
}  // namespace

std::ofstream FileWriter::open(const std::string& name, const std::string& header) {
  std::ofstream out(dir_ / name);
  if (!out) throw std::runtime_error("cannot write " + (dir_ / name).string());
  out << header << "\n";
  return out;
}

FileWriter::FileWriter(const std::filesystem::path& dir, const sim::ScenarioConfig& scenario,
                       std::vector<std::uint32_t> extra_imu_ids,
                       std::vector<std::uint32_t> extra_receiver_ids)
    : dir_(dir), unit_ids_(std::move(extra_imu_ids)), receiver_ids_(std::move(extra_receiver_ids)) {
  if (unit_ids_.size() != scenario.extra_imus.size() ||
      receiver_ids_.size() != scenario.extra_receivers.size())
    throw std::invalid_argument("FileWriter: " + std::to_string(unit_ids_.size()) + " ids for " +
                                std::to_string(scenario.extra_imus.size()) +
                                " further IMU units, " + std::to_string(receiver_ids_.size()) +
                                " ids for " + std::to_string(scenario.extra_receivers.size()) +
                                " further receivers");
  std::filesystem::create_directories(dir_);
  imu_ = open(
      "imu.csv",
      "time_gps_ns,interval_ns,delta_vel_x_mps,delta_vel_y_mps,delta_vel_z_mps,delta_angle_x_rad,"
      "delta_angle_y_rad,delta_angle_z_rad");
  raw_ = open("imu_raw.csv",
              "time_gps_ns,rate_x_radps,rate_y_radps,rate_z_radps,specific_force_x_mps2,specific_"
              "force_y_mps2,"
              "specific_force_z_mps2");
  gnss_ = open("gnss.csv",
               "time_gps_ns,sv_id,pseudorange_m,pseudorange_rate_mps,sat_x_m,sat_y_m,sat_z_m,sat_"
               "vx_mps,sat_vy_mps,"
               "sat_vz_mps,sat_clock_correction_m,cn0_dbhz,elevation_rad");
  fix_ = open("gnss_fix.csv",
              "time_gps_ns,valid,latitude_rad,longitude_rad,height_m,vel_n_mps,vel_e_mps,vel_d_mps,"
              "sigma_n_m,"
              "sigma_e_m,sigma_d_m,num_satellites,pdop");
  star_ = open("star_tracker.csv", "time_gps_ns,qw,qx,qy,qz,sigma_x_rad,sigma_y_rad,sigma_z_rad");
  if (!unit_ids_.empty())
    units_ = open("imu_units.csv",
                  "sensor_id,time_gps_ns,interval_ns,delta_vel_x_mps,delta_vel_y_mps,"
                  "delta_vel_z_mps,delta_angle_x_rad,delta_angle_y_rad,delta_angle_z_rad,"
                  "accel_bias_x_mps2,accel_bias_y_mps2,accel_bias_z_mps2,gyro_bias_x_radps,"
                  "gyro_bias_y_radps,gyro_bias_z_radps");
  if (!receiver_ids_.empty())
    receivers_ = open("gnss_receivers.csv",
                      "receiver_id,time_gps_ns,sv_id,pseudorange_m,pseudorange_rate_mps,sat_x_m,"
                      "sat_y_m,sat_z_m,sat_vx_mps,sat_vy_mps,sat_vz_mps,sat_clock_correction_m,"
                      "cn0_dbhz,elevation_rad");
  truth_ = open(
      "truth.csv",
      "time_gps_ns,latitude_rad,longitude_rad,height_m,vel_n_mps,vel_e_mps,vel_d_mps,qw,qx,qy,qz,"
      "roll_rad,pitch_rad,yaw_rad,accel_bias_x_mps2,accel_bias_y_mps2,accel_bias_z_mps2,"
      "gyro_bias_x_radps,gyro_bias_y_radps,gyro_bias_z_radps");
  std::ofstream faults =
      open("faults.csv",
           "kind,start_s,end_s,sensor,axis,sv_id,magnitude,slope_mps,saturation_m,vector_x,"
           "vector_y,vector_z,unit,bias_slope_per_s,bias_saturation");
  for (const auto& f : scenario.faults.faults()) {
    // Slopes and saturations: a pseudorange ramp's in slope_mps and saturation_m, an IMU bias
    // ramp's in bias_slope_per_s [m/s^2 or rad/s per s] and bias_saturation [m/s^2 or rad/s].
    const bool imu_ramp = f.kind == sim::FaultKind::kImuBiasRamp;
    faults << sim::faultKindName(f.kind) << "," << num(f.start_s) << ","
           << (f.end_s > 1e299 ? std::string("inf") : num(f.end_s)) << ","
           << (f.sensor == sim::SensorKind::kGyro ? "gyro" : "accelerometer") << "," << f.axis
           << "," << f.sv_id << "," << num(f.magnitude) << "," << num(imu_ramp ? 0.0 : f.slope)
           << "," << num(imu_ramp ? 0.0 : f.saturation) << "," << vec(f.vector) << "," << f.unit
           << "," << num(imu_ramp ? f.slope : 0.0) << "," << num(imu_ramp ? f.saturation : 0.0)
           << "\n";
  }
}

void FileWriter::writeSatellites(std::ofstream& out, const std::string& prefix,
                                 const sim::GnssEpoch& e) {
  for (const auto& s : e.satellites) {
    out << prefix << e.time_ns << "," << s.sv_id << "," << num(s.pseudorange_m) << ","
        << num(s.pseudorange_rate_mps) << "," << vec(s.sat_pos_ecef_m) << ","
        << vec(s.sat_vel_ecef_mps) << "," << num(s.sat_clock_correction_m) << "," << num(s.cn0_dbhz)
        << "," << num(s.elevation_rad) << "\n";
  }
}

void FileWriter::writeUnits(const sim::SensorFrame& f) {
  for (std::size_t k = 0; k < f.extra_imus.size() && k < unit_ids_.size(); ++k) {
    const sim::UnitImuIncrement& u = f.extra_imus[k];
    units_ << unit_ids_[k] << "," << f.time_ns << "," << std::llround(u.increment.interval_s * 1e9)
           << "," << vec(u.increment.delta_vel_b_mps) << "," << vec(u.increment.delta_angle_b_rad)
           << "," << vec(u.truth_accel_bias_u_mps2) << "," << vec(u.truth_gyro_bias_u_radps)
           << "\n";
    ++counts_.unit_increments;
  }
}

void FileWriter::write(const sim::SensorFrame& f) {
  const auto& inc = f.increment;
  imu_ << f.time_ns << "," << std::llround(inc.interval_s * 1e9) << "," << vec(inc.delta_vel_b_mps)
       << "," << vec(inc.delta_angle_b_rad) << "\n";
  ++counts_.imu;
  for (std::size_t i = 0; i < f.raw.samples.size(); ++i) {
    const auto& s = f.raw.samples[i];
    const auto t =
        f.raw.first_time_ns + std::llround(static_cast<double>(i) * f.raw.sample_period_s * 1e9);
    raw_ << t << "," << vec(s.angular_rate_b_radps) << "," << vec(s.specific_force_b_mps2) << "\n";
  }
  ++counts_.raw;
  writeUnits(f);
  for (std::size_t k = 0; f.has_extra_gnss && k < f.extra_gnss.size() && k < receiver_ids_.size();
       ++k) {
    if (f.extra_gnss_silent[k]) continue;  // that receiver is out
    writeSatellites(receivers_, std::to_string(receiver_ids_[k]) + ",", f.extra_gnss[k]);
    ++counts_.receiver_epochs;
  }
  if (f.has_gnss) {
    writeSatellites(gnss_, "", f.gnss);
    ++counts_.gnss_epochs;
    const auto& x = f.fix;
    fix_ << x.time_ns << "," << (x.valid ? 1 : 0) << "," << num(x.position.latitude_rad) << ","
         << num(x.position.longitude_rad) << "," << num(x.position.height_m) << ","
         << vec(x.vel_ned_mps) << "," << vec(x.pos_sigma_ned_m) << "," << x.num_satellites << ","
         << num(x.pdop) << "\n";
    ++counts_.gnss_fixes;
  }
  if (f.has_star_tracker) {
    const auto& q = f.star_tracker.q_b_to_i;
    star_ << f.star_tracker.time_ns << "," << num(q.w()) << "," << num(q.x()) << "," << num(q.y())
          << "," << num(q.z()) << "," << vec(f.star_tracker.sigma_b_rad) << "\n";
    ++counts_.star_tracker;
  }
  const auto& t = f.truth;
  const Eigen::Vector3d rpy = core::eulerFromDcm(t.q_b_to_n.toRotationMatrix());
  truth_ << f.time_ns << "," << num(t.position.latitude_rad) << "," << num(t.position.longitude_rad)
         << "," << num(t.position.height_m) << "," << vec(t.vel_ned_mps) << ","
         << num(t.q_b_to_n.w()) << "," << num(t.q_b_to_n.x()) << "," << num(t.q_b_to_n.y()) << ","
         << num(t.q_b_to_n.z()) << "," << vec(rpy) << "," << vec(f.truth_accel_bias_b_mps2) << ","
         << vec(f.truth_gyro_bias_b_radps) << "\n";
}

}  // namespace navbus::sensor_sim
