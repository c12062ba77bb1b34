// The real car (tests/data/real/drive_0708) through navbus import, navbus offline --recording
// and navbus benchmark real-car: the import's counts, and the benchmark's scores held to what
// the shipped configuration measured (docs/real_data.md), so that a change that loses accuracy
// on real data fails here. The targets are not met yet; the bounds say where we are.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <unistd.h>

#include "navbus/bus/config.hpp"
#include "navbus/evaluation/imu_noise_survey.hpp"
#include "navbus/evaluation/mounting_calibration.hpp"
#include "navbus/evaluation/real_car_benchmark.hpp"
#include "navbus/evaluation/recording_runner.hpp"
#include "navbus/evaluation/time_offset_calibration.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/importers/importer.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/records/csv_table.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using namespace navbus;

namespace {
const fs::path kConfig(navbus::test_paths::configDir());

fs::path workDir(const std::string& name) {
  const fs::path dir =
      fs::path(navbus::test_paths::workDir()) / (name + "-" + std::to_string(getpid()));
  fs::remove_all(dir);
  return dir;
}
}  // namespace

TEST(RealCar, TheDriveWithFifteenSecondOutagesScoresAsMeasured) {
  const fs::path out = workDir("real-car");
  evaluation::RealCarOptions o;
  o.dataset = (kConfig / "datasets/drive_0708.yaml").string();
  o.filter = (kConfig / "filter_drive_0708.yaml").string();
  o.outages = (kConfig / "datasets/drive_0708_outages.txt").string();
  o.out_dir = out.string();
  o.smooth = true;
  ASSERT_EQ(evaluation::runRealCarBenchmark(o), 0);

  const records::CsvTable table = records::readCsv(out / "outages.csv");
  // All eleven are scored: the first starts 2.3 s after the car moves, and the filter has its
  // heading from the GNSS course at 1 m/s (alignment.course_min_speed_mps), 52 of its fixed
  // epochs after that.
  ASSERT_EQ(table.rows.size(), 11u);
  double end_sum = 0.0, worst = 0.0, squares = 0.0, inside = 0.0;
  std::size_t epochs = 0;
  for (const auto& row : table.rows) {
    const double n = std::stod(row[table.column("epochs")]);
    EXPECT_EQ(n, row[table.column("outage")] == "1" ? 52.0 : 60.0) << "15 s of 4 Hz fixed epochs";
    const double end = std::stod(row[table.column("end_error_m")]);
    end_sum += end;
    worst = std::max(worst, end);
    squares += std::pow(std::stod(row[table.column("rms_m")]), 2) * n;
    inside += std::stod(row[table.column("inside_3sigma")]) * n;
    epochs += static_cast<std::size_t>(n);
  }
  const double mean_end = end_sum / 11.0;
  const double rms = std::sqrt(squares / static_cast<double>(epochs));
  std::printf(
      "drive_0708: outage end mean %.2f m, worst %.2f m, RMS %.2f m, inside 3 sigma %.1f %%\n",
      mean_end, worst, rms, 100.0 * inside / static_cast<double>(epochs));
  // Measured 2.03 / 4.26 / 1.17 m and 100 % with the constraint taking the body's squat
  // (2.03 / 4.05 / 1.17 m without), the IMU's noise measured in motion, every
  // stage estimating every state and the fix's position error as states (2.13 / 3.91 / 1.20 m
  // and 96.6 % with the noise at rest; 2.59 / 8.08 / 1.52 m and 90.0 % with seed 004's reduced
  // stages; 3.27 / 7.89 / 1.83 m and 69.8 % over outages 2-11 before the time offsets; targets
  // 3.0 / 6.0 m mean / worst end, 95 % inside 3 sigma).
  EXPECT_LT(mean_end, 2.4);
  EXPECT_LT(worst, 5.0);
  EXPECT_LT(rms, 1.4);
  EXPECT_GT(inside / static_cast<double>(epochs), 0.98);

  // scores.csv: the same figures, GNSS-available, and the smoother's over the same outages.
  const records::CsvTable scores = records::readCsv(out / "scores.csv");
  ASSERT_EQ(scores.rows.size(), 2u);
  const auto value = [&](std::size_t row, const char* column) {
    return std::stod(scores.rows[row][scores.column(column)]);
  };
  EXPECT_EQ(scores.rows[0][scores.column("run")], "filter");
  EXPECT_NEAR(value(0, "end_mean_m"), mean_end, 1e-3);
  EXPECT_NEAR(value(0, "rms_m"), rms, 1e-3);
  EXPECT_LT(value(0, "available_rms_m"), 0.03);  // measured 0.023 m (0.047 m before)
  EXPECT_EQ(scores.rows[1][scores.column("run")], "smoothed");
  // Measured: the smoothed outage ends 0.02 m on average, the largest error inside an outage
  // 0.44 m (target 0.5 m), RMS 0.16 m (target 0.25 m), with GNSS 0.033 m (1.56 / 0.54 /
  // 0.097 m before the smoother took the resets as jumps and the stages estimated every state).
  EXPECT_LT(value(1, "end_mean_m"), 0.05);
  EXPECT_LT(value(1, "max_worst_m"), 0.5);
  EXPECT_LT(value(1, "rms_m"), 0.25);
  EXPECT_LT(value(1, "available_rms_m"), 0.05);
  EXPECT_LT(value(1, "rms_m"), 0.5 * rms);  // the smoother at least halves the causal RMS
  // Protection levels from the filter's own GLR on the fixes (integrity block): measured 2,029
  // judged epochs, 95.2 % available, none beyond its HPL or VPL (largest e_h / HPL 0.67).
  EXPECT_EQ(value(0, "pl_epochs"), value(0, "pl_monitored"));
  EXPECT_GT(value(0, "pl_available"), 0.9 * value(0, "pl_epochs"));
  EXPECT_EQ(value(0, "pl_misleading_h"), 0.0);
  EXPECT_EQ(value(0, "pl_misleading_v"), 0.0);

  // coverage.csv: the honesty table, causal and smoothed, outages and GNSS available.
  const records::CsvTable coverage = records::readCsv(out / "coverage.csv");
  ASSERT_EQ(coverage.rows.size(), 4u);
  const auto cover = [&](std::size_t row, const char* column) {
    return std::stod(coverage.rows[row][coverage.column(column)]);
  };
  EXPECT_EQ(coverage.rows[0][coverage.column("run")], "causal");
  EXPECT_EQ(coverage.rows[0][coverage.column("group")], "outages");
  EXPECT_EQ(cover(0, "epochs"), static_cast<double>(epochs));
  EXPECT_NEAR(cover(0, "inside_3sigma_h"), value(0, "inside_3sigma"), 1e-4);
  EXPECT_NEAR(cover(1, "inside_3sigma_h"), value(0, "available_inside_3sigma"), 1e-4);
  EXPECT_NEAR(cover(2, "inside_3sigma_h"), value(1, "inside_3sigma"), 1e-4);
  // Measured: GNSS available 99.2 % inside 3 sigma_h (target 95 %; 91.4 % without the fix's
  // error states), 0.5 % of those epochs flagged; no outage epoch flagged. Smoothed: outages
  // 100 %, GNSS available 95.9 % (target 95 % each).
  EXPECT_GT(cover(1, "inside_3sigma_h"), 0.98);
  EXPECT_LT(cover(1, "flagged"), 0.02);
  EXPECT_EQ(cover(0, "flagged"), 0.0);
  EXPECT_GT(cover(2, "inside_3sigma_h"), 0.95);
  EXPECT_GT(cover(3, "inside_3sigma_h"), 0.95);
  for (std::size_t r = 0; r < 4; ++r) {
    EXPECT_LE(cover(r, "inside_1sigma_h"), cover(r, "inside_2sigma_h"));
    EXPECT_LE(cover(r, "inside_2sigma_h"), cover(r, "inside_3sigma_h"));
  }

  // The solution file: antenna positions at the IMU's rate with their sigmas.
  const records::CsvTable sol = records::readCsv(out / "solution.csv");
  EXPECT_GT(sol.rows.size(), 45'000u);
  for (const char* column : {"gpst_s", "lat_deg", "lon_deg", "height_m", "sigma_h_m", "sigma_v_m"})
    EXPECT_TRUE(sol.has(column)) << column;
  fs::remove_all(out);
}

TEST(RealCar, TheImportedRecordingRunsOfflineWithEveryIncrement) {
  const fs::path out = workDir("real-car-offline");
  const std::string filter = (kConfig / "filter_drive_0708.yaml").string();
  importers::importDataset(importers::readDatasetDescription(kConfig / "datasets/drive_0708.yaml"),
                           out / "recording");
  evaluation::RecordingSetup setup;
  setup.dir = out / "recording";
  setup.filter = bus::parseFile(filter, nav_filter::parseFilterConfig);
  std::size_t solutions = 0;
  const auto r = evaluation::runRecording(setup, [&](const NavigationSolution&) { ++solutions; });
  EXPECT_EQ(r.fixes_withheld, 0u);
  // Every one of the 54,859 increments reached the engine: integrated, or taken by the
  // alignment before the filter started.
  std::smatch integrated, aligning;
  ASSERT_TRUE(std::regex_search(r.summary, integrated, std::regex("increments integrated (\\d+)")));
  ASSERT_TRUE(
      std::regex_search(r.summary, aligning, std::regex("aligned after (\\d+) increments")));
  EXPECT_EQ(std::stoul(integrated[1]) + std::stoul(aligning[1]), 54'859u) << r.summary;
  EXPECT_NE(r.summary.find("refused by the engine 0"), std::string::npos) << r.summary;
  EXPECT_NE(r.summary.find("inertial gaps 0"), std::string::npos) << r.summary;
  EXPECT_GT(solutions, 45'000u);
  // Every fused fix's innovations, in metres: their normalized squares are the summary's NIS.
  std::smatch fused;
  ASSERT_TRUE(std::regex_search(r.summary, fused, std::regex("fixes fused (\\d+)")));
  ASSERT_EQ(r.fix_innovations.size(), std::stoul(fused[1]));
  double position_nis = 0.0, velocity_nis = 0.0;
  std::size_t alarmed = 0;
  for (const core::FixInnovation& f : r.fix_innovations) {
    position_nis += f.position_m.cwiseQuotient(f.position_sigma_m).squaredNorm();
    velocity_nis += f.velocity_mps.cwiseQuotient(f.velocity_sigma_mps).squaredNorm();
    alarmed += f.consistent ? 0 : 1;
  }
  EXPECT_NEAR(position_nis, r.fix_position_nis.nis_sum, 1e-9 * r.fix_position_nis.nis_sum);
  EXPECT_NEAR(velocity_nis, r.fix_velocity_nis.nis_sum, 1e-9 * r.fix_velocity_nis.nis_sum);
  // The monitor's verdict is carried: measured 14 of 1,910 fixes fused during an alarm.
  EXPECT_GT(alarmed, 0u);
  EXPECT_LT(alarmed, r.fix_innovations.size() / 50);
  // The fixed epochs fuse to about 2 cm: the innovations' sigmas say so, in metres.
  EXPECT_LT(r.fix_innovations.back().position_sigma_m.maxCoeff(), 0.1);

  // The configuration's noise densities are navbus allan's in motion: the standing start's
  // 1-s white noise times how much larger the one-sample Allan deviation is while driving.
  const auto rest = evaluation::surveyImuNoise((out / "recording").string(), 0.0, 30.0);
  const auto motion = evaluation::surveyImuNoise((out / "recording").string(), 60.0, 540.0);
  const evaluation::MotionNoise n = evaluation::motionNoise(rest, motion);
  EXPECT_NEAR(n.accel_ratio, 3.98, 0.01);  // the vibration in motion, measured
  EXPECT_NEAR(n.gyro_ratio, 2.43, 0.01);
  const core::FilterTuning& t = setup.filter.engine.tuning;
  EXPECT_NEAR(n.accel_density, t.accel_noise_mps2_per_sqrthz, 0.002 * n.accel_density);
  EXPECT_NEAR(n.gyro_density, t.gyro_noise_radps_per_sqrthz, 0.002 * n.gyro_density);

  // The constraint's squat and dive are navbus calibrate mounting's: the smoothed run, GNSS
  // never withheld, the velocity's pitch in body axes against the longitudinal acceleration.
  evaluation::configureMountingRun(setup);
  const auto smoothed = evaluation::runRecording(setup);
  const evaluation::MountingResidual m =
      evaluation::mountingResidual(smoothed.smoothed, evaluation::StraightDriving{});
  const double deg = M_PI / 180.0;
  EXPECT_NEAR(m.velocity_pitch_per_accel_rad_per_mps2,
              setup.filter.engine.mdf.nhc_velocity_pitch_per_accel_rad_per_mps2, 0.001 * deg);
  EXPECT_LT(m.velocity_pitch_accel_correlation, -0.5);  // measured -0.57
  EXPECT_NEAR(m.pitch_rad, -0.072 * deg, 0.01 * deg);   // the published pitch holds
  EXPECT_NEAR(m.yaw_rad, 0.896 * deg, 0.01 * deg);
  EXPECT_LT(m.corrected_rms_mps.maxCoeff(), setup.filter.engine.mdf.nhc_sigma_mps);
  fs::remove_all(out);
}

TEST(RealCar, TwentySecondOutagesStayInsideTheirOwnThreeSigma) {
  // The 20 s every 60 s schedule (another the shipped list was not tuned on), same
  // configuration: measured 100 % of the outage epochs inside 3 sigma_h (99.7 % before the
  // filter raised its bias sigmas at an alarm, 91.7 % before the constraint took the body's
  // squat), ends 2.51 / 14.33 m mean / worst (3.36 / 14.33 m before).
  const fs::path out = workDir("real-car-20s");
  evaluation::RealCarOptions o;
  o.dataset = (kConfig / "datasets/drive_0708.yaml").string();
  o.filter = (kConfig / "filter_drive_0708.yaml").string();
  o.schedule = evaluation::OutageSchedule{20.0, 60.0, 243298.499};
  o.out_dir = out.string();
  ASSERT_EQ(evaluation::runRealCarBenchmark(o), 0);
  const records::CsvTable scores = records::readCsv(out / "scores.csv");
  ASSERT_EQ(scores.rows.size(), 1u);
  const auto value = [&](const char* column) {
    return std::stod(scores.rows[0][scores.column(column)]);
  };
  EXPECT_GT(value("inside_3sigma"), 0.95);  // the target on every schedule
  EXPECT_LT(value("end_mean_m"), 4.0);
  fs::remove_all(out);
}

TEST(RealCar, AnAccelerometerStepIsFlaggedAndTheBiasesLearntAgain) {
  // 0.2 m/s^2 on the sensor's x axis (the car's backward axis) from 200 s after the first
  // sample, while the car stands; it starts 6 s later. Measured with the shipped configuration:
  // flagged 9.03 s after the onset, 10 of the 36 fixed epochs before that outside 3 sigma_h
  // (0.35 m at most), and the outages 100 % inside 3 sigma_h (78.5 % without raising the bias
  // sigmas at the alarm, consistency.inflate_imu_biases_on_alarm).
  const fs::path out = workDir("real-car-accel-step");
  evaluation::RealCarOptions o;
  o.dataset = (kConfig / "datasets/drive_0708.yaml").string();
  o.filter = (kConfig / "filter_drive_0708.yaml").string();
  o.outages = (kConfig / "datasets/drive_0708_outages.txt").string();
  o.imu_step = importers::ImuStep{false, 0, 0.2, 200.0};
  o.out_dir = out.string();
  ASSERT_EQ(evaluation::runRealCarBenchmark(o), 0);
  const records::CsvTable step = records::readCsv(out / "step.csv");
  ASSERT_EQ(step.rows.size(), 1u);
  const std::string flagged_after = step.rows[0][step.column("first_flag_after_s")];
  ASSERT_FALSE(flagged_after.empty()) << "the step was never flagged";
  EXPECT_LT(std::stod(flagged_after), 15.0);
  EXPECT_LT(std::stod(step.rows[0][step.column("largest_error_m")]), 0.5);
  const records::CsvTable scores = records::readCsv(out / "scores.csv");
  EXPECT_GT(std::stod(scores.rows[0][scores.column("inside_3sigma")]), 0.95);
  fs::remove_all(out);
}

namespace {
/// The shipped drive configuration with the IMU's noise densities measured at rest (what a
/// user who surveyed the IMU only standing would configure), and the given extra keys.
fs::path driveConfigWithRestNoise(const fs::path& dir, const std::string& extra) {
  std::ifstream in(kConfig / "filter_drive_0708.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  for (const auto& [from, to] :
       {std::pair<std::string, std::string>{"accel_noise_ug_per_sqrthz: 2483",
                                            "accel_noise_ug_per_sqrthz: 624"},
        {"gyro_arw_deg_per_sqrth: 4.67", "gyro_arw_deg_per_sqrth: 1.92"}}) {
    const std::size_t at = yaml.find(from);
    EXPECT_NE(at, std::string::npos) << "the shipped configuration no longer has " << from;
    if (at != std::string::npos) yaml.replace(at, from.size(), to);
  }
  fs::create_directories(dir);
  const fs::path out = dir / "filter.yaml";
  std::ofstream(out) << yaml << "\n" << extra << "\n";
  return out;
}

double outageCoverage(const fs::path& filter, const fs::path& out) {
  evaluation::RealCarOptions o;
  o.dataset = (kConfig / "datasets/drive_0708.yaml").string();
  o.filter = filter.string();
  o.outages = (kConfig / "datasets/drive_0708_outages.txt").string();
  o.out_dir = out.string();
  EXPECT_EQ(evaluation::runRealCarBenchmark(o), 0);
  const records::CsvTable scores = records::readCsv(out / "scores.csv");
  EXPECT_EQ(scores.rows.size(), 1u);
  return scores.rows.empty() ? 0.0 : std::stod(scores.rows[0][scores.column("inside_3sigma")]);
}
}  // namespace

TEST(RealCar, TheProcessNoiseAdaptsUpFromTheDensitiesAtRest) {
  // The noise densities at rest are 4.0x (accelerometers) and 2.4x (gyros) below those in
  // motion. Measured on the 15 s schedule: 93.7 % of the outage epochs inside 3 sigma_h with
  // them, 100.0 % with the process noise adapting from the fixes' innovations (its scale up to
  // 25, the ceiling; 3.2 at the end).
  const fs::path dir = workDir("real-car-rest-noise");
  const double fixed = outageCoverage(driveConfigWithRestNoise(dir / "fixed", ""), dir / "fixed");
  const double adapted =
      outageCoverage(driveConfigWithRestNoise(dir / "adapted",
                                              "adaptive_process_noise: {enabled: true, "
                                              "ceiling: 25}"),
                     dir / "adapted");
  std::printf(
      "drive_0708 with the noise at rest: inside 3 sigma_h %.1f %% fixed, %.1f %% "
      "adapted\n",
      100.0 * fixed, 100.0 * adapted);
  EXPECT_LT(fixed, 0.95);
  EXPECT_GT(adapted, 0.99);
  fs::remove_all(dir);
}

TEST(RealCar, TheMountingStatesLearnThePitchTheCalibrationReads) {
  // The mounting-misalignment states (1 deg a priori) with the constraint beside the fixes, over
  // the whole drive (no outage): they learn the forward axis's pitch that navbus calibrate
  // mounting reads from the smoothed velocity (-0.072 deg; measured -0.069 +- 0.029 deg), and its
  // yaw to a tenth of a degree (+0.38 +- 0.11 deg; the calibration's +0.9 deg holds the smoothed
  // heading's own error too).
  const fs::path out = workDir("real-car-mounting");
  importers::importDataset(importers::readDatasetDescription(kConfig / "datasets/drive_0708.yaml"),
                           out / "recording");
  evaluation::RecordingSetup setup;
  setup.dir = out / "recording";
  setup.filter =
      bus::parseFile((kConfig / "filter_drive_0708.yaml").string(), nav_filter::parseFilterConfig);
  setup.filter.engine.tuning.mounting_misalignment_sigma_rad = 1.0 * M_PI / 180.0;
  setup.filter.engine.mdf.nhc_with_gnss = true;
  const auto r = evaluation::runRecording(setup);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      r.summary, m,
      std::regex("mounting misalignment \\(roll, pitch, yaw\\) (\\S+) / (\\S+) / (\\S+) deg "
                 "\\(1 sigma (\\S+) / (\\S+) / (\\S+)\\)")))
      << r.summary;
  const double pitch = std::stod(m[2]), yaw = std::stod(m[3]);
  const double pitch_sigma = std::stod(m[5]), yaw_sigma = std::stod(m[6]);
  std::printf("drive_0708 mounting: pitch %.3f +- %.3f deg, yaw %.3f +- %.3f deg\n", pitch,
              pitch_sigma, yaw, yaw_sigma);
  EXPECT_LT(pitch_sigma, 0.1);  // learnt from 1 deg
  EXPECT_LT(yaw_sigma, 0.3);
  EXPECT_NEAR(pitch, -0.072, 3.0 * pitch_sigma + 0.02);
  EXPECT_GT(yaw, 0.0);  // the calibration's sign
  fs::remove_all(out);
}

TEST(ImuNoise, TheDensitiesInMotionAreTheRestsScaledByTheOneSampleVibration) {
  evaluation::ImuNoiseSurvey rest, motion;
  rest.curve.push_back({0.01, {0.05, 0.05, 0.05, 0.01, 0.01, 0.01}});
  motion.curve.push_back({0.01, {0.2, 0.2, 0.2, 0.03, 0.03, 0.03}});
  rest.white_noise = {6e-3, 6e-3, 6e-3, 5e-4, 5e-4, 5e-4};
  const evaluation::MotionNoise n = evaluation::motionNoise(rest, motion);
  EXPECT_DOUBLE_EQ(n.accel_ratio, 4.0);
  EXPECT_DOUBLE_EQ(n.gyro_ratio, 3.0);
  EXPECT_DOUBLE_EQ(n.accel_density, 0.024);
  EXPECT_DOUBLE_EQ(n.gyro_density, 1.5e-3);
  // Stretches sampled at other rates do not compare.
  motion.curve.front().tau_s = 0.02;
  EXPECT_THROW(evaluation::motionNoise(rest, motion), bus::ConfigError);
}

// The walk (config/datasets/walk_0827.yaml): its IMU tightly coupled with its own GPS
// pseudoranges and Doppler (4 satellites with broadcast ephemeris), scored against the
// receiver's fixed RTK epochs beside single point positioning of the same pseudoranges; the GLR
// on the clean walk, and on a ramp injected into one real satellite.
namespace {

evaluation::RecordingResult runWalk(const fs::path& recording, bool with_fault_manager,
                                    bool adaptive_noise = false) {
  evaluation::RecordingSetup setup;
  setup.dir = recording;
  setup.filter = bus::parseFile((kConfig / "filter_walk_0827_tc.yaml").string(),
                                nav_filter::parseFilterConfig);
  setup.filter.engine.adaptive_noise.enabled = adaptive_noise;
  setup.filter.engine.adaptive_process_noise.enabled = adaptive_noise;
  if (with_fault_manager)
    setup.fault_manager = bus::parseFile((kConfig / "fault_manager.yaml").string(),
                                         fault_manager::parseFaultManagerConfig);
  return evaluation::runRecording(setup);
}

}  // namespace

TEST(RealWalk, TightlyCoupledOnItsOwnPseudorangesBesideSinglePointPositioning) {
  const fs::path out = workDir("real-walk");
  evaluation::RealCarOptions o;
  o.dataset = (kConfig / "datasets/walk_0827.yaml").string();
  o.filter = (kConfig / "filter_walk_0827_tc.yaml").string();
  o.out_dir = out.string();
  ASSERT_EQ(evaluation::runRealCarBenchmark(o), 0);
  const records::CsvTable scores = records::readCsv(out / "scores.csv");
  ASSERT_EQ(scores.rows.size(), 2u);
  const auto value = [&](std::size_t row, const char* column) {
    return std::stod(scores.rows[row][scores.column(column)]);
  };
  EXPECT_EQ(scores.rows[0][scores.column("run")], "filter");
  EXPECT_EQ(scores.rows[1][scores.column("run")], "spp");
  const double filter_rms = value(0, "available_rms_m");
  const double spp_rms = value(1, "available_rms_m");
  std::printf(
      "walk_0827: tightly coupled %.2f m, single point %.2f m horizontal RMS; inside 3 "
      "sigma %.1f %% / %.1f %%\n",
      filter_rms, spp_rms, 100.0 * value(0, "available_inside_3sigma"),
      100.0 * value(1, "available_inside_3sigma"));
  // Measured 7.67 m against 8.29 m (349 fixed epochs; the filter aligns after 12.6 s, 296).
  EXPECT_LT(filter_rms, spp_rms);
  // Both sigmas hold their errors: the 4 satellites' errors are slow biases, which the filter
  // models as Gauss-Markov states (measured 100 % inside 3 sigma, 44 % inside 1 sigma; 0.7 %
  // inside 3 sigma with white measurement noise only).
  EXPECT_GT(value(1, "available_inside_3sigma"), 0.95);
  EXPECT_GE(value(0, "available_inside_3sigma"), 0.90);
  EXPECT_LE(filter_rms, 7.69);  // no worse than with white noise only
  // Protection levels on every judged epoch: never below the true error while available
  // (measured: 123 of 296 available, largest e_h / HPL 0.25, e_v / VPL 0.20).
  EXPECT_EQ(value(0, "pl_monitored"), value(0, "available_epochs"));
  EXPECT_GT(value(0, "pl_available"), 0.0);
  EXPECT_EQ(value(0, "pl_misleading_h"), 0.0);
  EXPECT_EQ(value(0, "pl_misleading_v"), 0.0);
  EXPECT_GT(value(0, "available_epochs"), 290.0);
  EXPECT_EQ(value(1, "available_epochs"), 349.0);
  fs::remove_all(out);
}

TEST(RealWalk, TheGlrOnTheCleanWalkAndOnARampInOneRealSatellite) {
  const fs::path clean_dir = workDir("walk-clean");
  auto d = importers::readDatasetDescription(kConfig / "datasets/walk_0827.yaml");
  importers::importDataset(d, clean_dir);
  const evaluation::RecordingResult clean = runWalk(clean_dir, true);
  std::size_t detected = 0;
  for (const auto& decision : clean.decisions) {
    if (decision.event() != navbus::EVENT_FAULT_DETECTED) continue;
    ++detected;
    // The one decision measured: G23's Doppler dips by 3-5 m/s for a second at 17:32:08-09
    // (its pseudorange rate against its own pseudoranges' differences), a real excursion.
    EXPECT_EQ(decision.sv_id(), 23) << "only G23's rate excursion is known";
  }
  EXPECT_LE(detected, 1u) << clean.fault_summary;

  const fs::path ramp_dir = workDir("walk-ramp");
  d.gnss_observations->ramp = importers::PseudorangeRamp{10, 2.0, 40.0};
  importers::importDataset(d, ramp_dir);
  const evaluation::RecordingResult ramp = runWalk(ramp_dir, true);
  const double first_epoch_s = 1440437439.748;  // 17:30:39.748 GPS, the RINEX file's first
  const auto g10 = std::find_if(ramp.decisions.begin(), ramp.decisions.end(), [](const auto& x) {
    return x.event() == navbus::EVENT_FAULT_DETECTED && x.sv_id() == 10;
  });
  ASSERT_NE(g10, ramp.decisions.end()) << ramp.fault_summary;
  const double after_onset_s =
      1e-9 * static_cast<double>(g10->time_gps_ns()) - first_epoch_s - 40.0;
  std::printf("walk_0827, 2 m/s ramp into G10 from 40 s: decided %.1f s after the onset\n",
              after_onset_s);
  EXPECT_GT(after_onset_s, 0.0);
  EXPECT_LT(after_onset_s, 15.0);  // measured 8.2 s (5.2 s with white range errors only)
  const auto exclusion =
      std::find_if(ramp.commands.begin(), ramp.commands.end(), [&](const navbus::FilterCommand& c) {
        return c.kind() == navbus::CMD_EXCLUDE_SATELLITE && c.decision_id() == g10->decision_id();
      });
  ASSERT_NE(exclusion, ramp.commands.end());
  EXPECT_EQ(exclusion->sv_id(), 10);
  EXPECT_EQ(exclusion->scope(), navbus::SCOPE_PSEUDORANGE);
  fs::remove_all(clean_dir);
  fs::remove_all(ramp_dir);
}

// Bounded adaptive noise does not adapt a fault away: with every stream's R adapting (window
// 20 epochs, ceiling 9) and the process noise adapting (memory 600 s, ceiling 9), the 2 m/s
// ramp into G10 is still decided and G10 excluded, and the scales stay at their ceilings or
// below while it grows.
TEST(RealWalk, AdaptiveNoiseLeavesTheRampVisible) {
  const fs::path ramp_dir = workDir("walk-ramp-adaptive");
  auto d = importers::readDatasetDescription(kConfig / "datasets/walk_0827.yaml");
  d.gnss_observations->ramp = importers::PseudorangeRamp{10, 2.0, 40.0};
  importers::importDataset(d, ramp_dir);
  const evaluation::RecordingResult ramp = runWalk(ramp_dir, true, true);
  const double first_epoch_s = 1440437439.748;
  const auto g10 = std::find_if(ramp.decisions.begin(), ramp.decisions.end(), [](const auto& x) {
    return x.event() == navbus::EVENT_FAULT_DETECTED && x.sv_id() == 10;
  });
  ASSERT_NE(g10, ramp.decisions.end()) << ramp.fault_summary;
  const double after_onset_s =
      1e-9 * static_cast<double>(g10->time_gps_ns()) - first_epoch_s - 40.0;
  std::printf(
      "walk_0827 with adaptive noise, 2 m/s ramp into G10: decided %.1f s after the onset\n",
      after_onset_s);
  EXPECT_GT(after_onset_s, 0.0);
  EXPECT_LT(after_onset_s, 15.0);
  // The diagnostics carry every stream's scale, bounded; the summary counts them.
  ASSERT_EQ(ramp.last_noise_scales.size(), 7u);
  for (const navbus::NoiseScale& n : ramp.last_noise_scales) {
    EXPECT_GE(n.scale(), 1.0);
    EXPECT_LE(n.scale(), 9.0);
  }
  EXPECT_NE(ramp.summary.find("adaptive noise"), std::string::npos) << ramp.summary;
  EXPECT_NE(ramp.summary.find("pseudorange_rate"), std::string::npos) << ramp.summary;
  // The 1 Hz pseudoranges' variance is nearly all R and the satellites' own errors: the
  // process noise's scale hardly moves from 1 (its diagnostics field says which).
  EXPECT_GE(ramp.last_process_noise_scale, 1.0);
  EXPECT_LE(ramp.last_process_noise_scale, 9.0);
  EXPECT_NE(ramp.summary.find("adaptive process noise"), std::string::npos) << ramp.summary;
  fs::remove_all(ramp_dir);
}

// navbus calibrate time-offset on the drive, on narrow grids about the shipped offsets (one
// round, 9 runs): it finds the IMU's delay from the position rows and the fix velocity's lag
// from the velocity rows, the values config/filter_drive_0708.yaml carries (-0.088 and -0.132 s
// from the full command's two rounds on the default grids).
TEST(RealCar, TheTimeOffsetsComeFromTheInnovations) {
  const fs::path out = workDir("time-offset");
  const auto dataset = importers::readDatasetDescription(kConfig / "datasets/drive_0708.yaml");
  importers::importDataset(dataset, out / "recording");
  evaluation::RecordingSetup setup;
  setup.dir = out / "recording";
  setup.filter =
      bus::parseFile((kConfig / "filter_drive_0708.yaml").string(), nav_filter::parseFilterConfig);
  // The grid is added to the configured IMU offset: start from the data set's alone. The
  // offsets come first, before the fix's error states, which take a part of the same
  // innovations (with them the velocity rows' NIS at the grid's edge is only 1.22 times its
  // minimum): the states off.
  setup.filter.imu.time_offset_ns = 0;
  setup.filter.engine.tuning.fix_position_error_sigma_h_m = 0.0;
  setup.filter.gnss_fix->velocity_time_offset_ns = -132'000'000;
  const auto imu = evaluation::searchImuTimeOffset(setup, {-0.14, -0.04, 0.02});
  ASSERT_FALSE(imu.at_edge);
  EXPECT_NEAR(imu.refined_s, -0.088, 0.01);
  setup.filter.imu.time_offset_ns = std::llround(imu.refined_s * 1e9);
  const auto velocity = evaluation::searchVelocityTimeOffset(setup, {-0.2, -0.08, 0.02});
  ASSERT_FALSE(velocity.at_edge);
  EXPECT_NEAR(velocity.refined_s, -0.132, 0.01);
  // The minimum is a real one: the mean NIS at the edges of each grid is larger by a margin.
  EXPECT_GT(imu.trials.front().mean_nis, 1.1 * imu.trials[imu.best].mean_nis);
  EXPECT_GT(velocity.trials.back().mean_nis, 1.3 * velocity.trials[velocity.best].mean_nis);
  fs::remove_all(out);
}
