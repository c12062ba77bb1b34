// navbus import's readers on the real logs (tests/data/real) and on every malformed case: a
// cut first or last line is skipped and reported, any other bad field is an error naming the
// file, the line and the column.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include <fmt/format.h>

#include "navbus/bus/config.hpp"
#include "navbus/core/math/units.hpp"
#include "navbus/gnss_data/rinex2.hpp"
#include "navbus/importers/dataset.hpp"
#include "navbus/importers/importer.hpp"
#include "navbus/importers/imu_csv.hpp"
#include "navbus/importers/imu_increments.hpp"
#include "navbus/importers/rinex_observations.hpp"
#include "navbus/importers/rtklib_pos.hpp"
#include "navbus/importers/rtklib_time_tag.hpp"
#include "navbus/records/csv_messages.hpp"
#include "test_paths.hpp"

using namespace navbus;
using namespace navbus::importers;
namespace fs = std::filesystem;

namespace {

const fs::path kReal = fs::path(navbus::test_paths::sourceDir()) / "tests/data/real";
const fs::path kDatasets = fs::path(navbus::test_paths::configDir()) / "datasets";

std::int64_t gpsNs(int y, int mo, int d, int h, int mi, double s) {
  return std::llround(gnss_data::gpsSecondsFromCalendar(y, mo, d, h, mi, 0.0)) * 1'000'000'000 +
         std::llround(s * 1e9);
}

/// This process's scratch directory, removed when the tests end.
struct ScratchDir {
  fs::path dir = fs::temp_directory_path() / ("navbus-importers-" + std::to_string(getpid()));
  ~ScratchDir() { fs::remove_all(dir); }
};

fs::path scratch(const std::string& name) {
  static const ScratchDir scratch_dir;
  fs::create_directories(scratch_dir.dir);
  return scratch_dir.dir / name;
}

fs::path writeText(const std::string& name, const std::string& text) {
  const fs::path p = scratch(name);
  std::ofstream(p) << text;
  return p;
}

/// The error text of `f`, or "" if it did not throw a ConfigError.
template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const bus::ConfigError& e) {
    return e.what();
  }
  return "";
}

ImuCsvDescription gpsSecondsCsv(const fs::path& file) {
  ImuCsvDescription d;
  d.file = file;
  d.time_source = ImuTimeSource::kGpsSeconds;
  d.sample_rate_hz = 100;
  return d;
}

}  // namespace

TEST(TimeTag, ReadsTheDrivesStartAndSpan) {
  const TimeTag tag = readTimeTag(kReal / "drive_0708/imu_1934.csv.tag");
  // README: start 2025-07-08 19:34:21.854 GPST, last tick 548,731 ms.
  EXPECT_EQ(tag.start_gps_ns, gpsNs(2025, 7, 8, 19, 34, 21.854));
  EXPECT_EQ(tag.lastTickMs(), 548'731u);
  EXPECT_GT(tag.records.size(), 1000u);
}

TEST(TimeTag, RefusesAnotherFileAndATruncatedOne) {
  EXPECT_NE(errorOf([] {
              readTimeTag(kReal / "drive_0708/imu_1934.csv");
            }).find("not an RTKLIB time-tag file"),
            std::string::npos);
  std::ifstream in(kReal / "drive_0708/imu_1934.csv.tag", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  bytes.resize(bytes.size() - 3);
  const fs::path cut = scratch("cut.tag");
  std::ofstream(cut, std::ios::binary) << bytes;
  EXPECT_NE(errorOf([&] { readTimeTag(cut); }).find("not a whole number of 8-byte records"),
            std::string::npos);
}

TEST(ImuCsv, TheDriveMapsItsDeviceClockOntoTheTimeTag) {
  const auto d = readDatasetDescription(kDatasets / "drive_0708.yaml");
  ASSERT_TRUE(d.imu);
  const ImuLog log = readImuCsv(*d.imu);
  EXPECT_TRUE(log.skipped.empty());
  ASSERT_EQ(log.samples.size(), 54'860u);
  const std::int64_t start = gpsNs(2025, 7, 8, 19, 34, 21.854);
  EXPECT_EQ(log.samples.front().time_gps_ns, start - 125'000'000);
  EXPECT_EQ(log.samples.back().time_gps_ns, start + 548'731'000'000 - 125'000'000);
  // The first line: 0.119,0.027,1.013 g and -0.671,3.082,0.198 deg/s.
  EXPECT_DOUBLE_EQ(log.samples.front().specific_force_s_mps2.z(), 1.013 * units::kStandardGravity);
  EXPECT_DOUBLE_EQ(log.samples.front().rate_s_radps.y(), 3.082 * units::kDeg);
}

TEST(ImuCsv, TheWalksCutFirstAndLastLinesAreSkippedAndReported) {
  const auto d = readDatasetDescription(kDatasets / "walk_0827.yaml");
  const ImuLog log = readImuCsv(*d.imu);
  ASSERT_EQ(log.skipped.size(), 2u);
  EXPECT_NE(log.skipped[0].find("line 1 skipped, cut at the start"), std::string::npos)
      << log.skipped[0];
  EXPECT_NE(log.skipped[1].find("line 20457 skipped, cut at the end"), std::string::npos)
      << log.skipped[1];
  EXPECT_EQ(log.samples.size(), 20'455u);
}

TEST(ImuCsv, AMalformedLineInsideTheLogIsAnErrorNamingFileLineAndColumn) {
  const std::string good = "0.1,0.0,1.0,0.5,0.0,0.0,";
  auto text = [&](const std::string& middle) {
    return good + "1.00\n" + good + "1.01\n" + middle + "\n" + good + "1.03\n";
  };
  const fs::path bad_number = writeText("bad_number.csv", text("0.1,0.0,x1.0,0.5,0.0,0.0,1.02"));
  std::string e = errorOf([&] { readImuCsv(gpsSecondsCsv(bad_number)); });
  EXPECT_NE(e.find("bad_number.csv line 3: column 2 (accel z): 'x1.0' is not a number"),
            std::string::npos)
      << e;
  const fs::path short_line = writeText("short_line.csv", text("0.1,0.0,1.0,0.5,0.0,1.02"));
  e = errorOf([&] { readImuCsv(gpsSecondsCsv(short_line)); });
  EXPECT_NE(e.find("short_line.csv line 3: 6 cells, no column 6 (time)"), std::string::npos) << e;
  const fs::path empty_cell = writeText("empty_cell.csv", text("0.1,0.0,1.0,,0.0,0.0,1.02"));
  e = errorOf([&] { readImuCsv(gpsSecondsCsv(empty_cell)); });
  EXPECT_NE(e.find("empty_cell.csv line 3: column 3 (gyro x): '' is not a number"),
            std::string::npos)
      << e;
  const fs::path back = writeText("back.csv", text(good + "1.005"));
  e = errorOf([&] { readImuCsv(gpsSecondsCsv(back)); });
  EXPECT_NE(e.find("back.csv line 3: column 6 (time): 1.005 is not after line 2's 1.01"),
            std::string::npos)
      << e;
  const fs::path inf = writeText("inf.csv", text("0.1,0.0,1.0,0.5,inf,0.0,1.02"));
  e = errorOf([&] { readImuCsv(gpsSecondsCsv(inf)); });
  EXPECT_NE(e.find("inf.csv line 3: column 4 (gyro y): 'inf' is not a number"), std::string::npos)
      << e;
  // The same faults on the first or last line are cuts: skipped, reported.
  const fs::path cut = writeText("cut.csv", "0,1.0,0.5,0.0,0.0,1.00\n" + good + "1.01\n" + good +
                                                "1.02\n" + "0.1,0.0,1.0,0.5,0.");
  const ImuLog log = readImuCsv(gpsSecondsCsv(cut));
  EXPECT_EQ(log.samples.size(), 2u);
  EXPECT_EQ(log.skipped.size(), 2u);
}

TEST(ImuCsv, ADeviceClockThatDoesNotSpanTheTimeTagIsAnotherLog) {
  ImuCsvDescription d;
  d.file = writeText("short_log.csv", "0,0,1,0,0,0,1000\n0,0,1,0,0,0,2000\n");
  d.time_source = ImuTimeSource::kDeviceTicks;
  d.time_tag = kReal / "drive_0708/imu_1934.csv.tag";
  d.sample_rate_hz = 100;
  const std::string e = errorOf([&] { readImuCsv(d); });
  EXPECT_NE(e.find("not the same log"), std::string::npos) << e;
}

TEST(ImuIncrements, TrapezoidalIntegralsOverTheSampleIntervals) {
  // A rate ramping linearly in time: the trapezoid is its exact integral.
  std::vector<ImuSample> samples;
  for (int k = 0; k < 5; ++k) {
    ImuSample s;
    s.time_gps_ns = 1'000'000'000 + k * 10'000'000 + (k == 3 ? 2'000'000 : 0);  // jitter
    const double t = 1e-9 * static_cast<double>(s.time_gps_ns);
    s.rate_s_radps = Eigen::Vector3d(0.1 * t, -0.2, 0.0);
    s.specific_force_s_mps2 = Eigen::Vector3d(0.0, 0.0, -9.8 + t);
    samples.push_back(s);
  }
  const auto inc = incrementsFromSamples(samples, 7);
  ASSERT_EQ(inc.size(), 4u);
  for (std::size_t k = 0; k < inc.size(); ++k) {
    const double t0 = 1e-9 * static_cast<double>(samples[k].time_gps_ns);
    const double t1 = 1e-9 * static_cast<double>(samples[k + 1].time_gps_ns);
    EXPECT_EQ(inc[k].sensor_id(), 7u);
    EXPECT_EQ(inc[k].seq(), k + 1);
    EXPECT_EQ(inc[k].time_gps_ns(), static_cast<std::uint64_t>(samples[k + 1].time_gps_ns));
    EXPECT_EQ(inc[k].interval_ns(), samples[k + 1].time_gps_ns - samples[k].time_gps_ns);
    EXPECT_NEAR(inc[k].delta_angle_b_rad()[0], 0.05 * (t1 * t1 - t0 * t0), 1e-15);
    EXPECT_NEAR(inc[k].delta_angle_b_rad()[1], -0.2 * (t1 - t0), 1e-15);
    EXPECT_NEAR(inc[k].delta_vel_b_mps()[2], -9.8 * (t1 - t0) + 0.5 * (t1 * t1 - t0 * t0), 1e-13);
  }
}

TEST(ImuIncrements, BlocksSpanTheirTimeAndTheTopicsBound) {
  std::vector<navbus::ImuIncrement> incs(300);
  for (std::size_t k = 0; k < incs.size(); ++k) {
    incs[k].sensor_id(1);
    incs[k].seq(k + 1);
    incs[k].interval_ns(10'000'000);
    incs[k].time_gps_ns(1'000'000'000 + (k + 1) * 10'000'000);
  }
  const auto tenths = blocksOf(incs, 0.1);
  ASSERT_EQ(tenths.size(), 30u);
  for (std::size_t b = 0; b < tenths.size(); ++b) {
    EXPECT_EQ(tenths[b].seq(), b + 1);
    EXPECT_EQ(tenths[b].increments().size(), 10u);
  }
  const auto bounded = blocksOf(incs, 1.0);  // 100 per second, at most 64 a block
  EXPECT_EQ(bounded.front().increments().size(), 64u);
}

TEST(RtklibPos, TheDrivesSolutionsWithTheirQualitiesAndEllipsoidalHeights) {
  const auto d = readDatasetDescription(kDatasets / "drive_0708.yaml");
  ASSERT_TRUE(d.gnss_solutions);
  const PosLog log = readPosFile(*d.gnss_solutions);
  EXPECT_EQ(log.epochs_by_quality[1], 2189u);
  EXPECT_EQ(log.epochs_by_quality[2], 8u);
  ASSERT_EQ(log.fixes.size(), 2197u);
  EXPECT_TRUE(log.has_velocity);
  const auto& first = log.fixes.front();
  // 2025/07/08 19:34:18.499 (1 ms early) 40.0966268 -105.1474483 1601.474 (hMSL) ... vn 0.010
  // ve -0.002 vu 0.009.
  EXPECT_EQ(first.time_gps_ns(), static_cast<std::uint64_t>(gpsNs(2025, 7, 8, 19, 34, 18.5)));
  EXPECT_DOUBLE_EQ(first.latitude_rad(), 40.0966268 * units::kDeg);
  EXPECT_DOUBLE_EQ(first.height_m(), 1601.474 - 21.387);
  EXPECT_DOUBLE_EQ(first.vel_ned_mps()[2], -0.009);
  EXPECT_DOUBLE_EQ(first.pos_sigma_ned_m()[0], 0.02);  // 0.0099 m raised to the fix floor
  EXPECT_EQ(first.num_satellites_used(), 21u);
  for (std::size_t i = 1; i < log.fixes.size(); ++i)
    ASSERT_EQ(log.fixes[i].time_gps_ns() - log.fixes[i - 1].time_gps_ns(), 250'000'000u);
}

TEST(RtklibPos, AQualityLeftOutIsCountedAndMissingVelocityMeansPositionOnly) {
  const std::string header =
      "%  GPST                  latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   "
      "sde(m)   sdu(m)\n";
  PosDescription d;
  d.file =
      writeText("no_velocity.pos", header +
                                       "2374 243258.500   40.1 -105.1 1600.0 1 20 0.01 0.01 0.02\n"
                                       "2374 243258.750   40.1 -105.1 1600.0 5 20 1.5 1.5 3.0\n");
  d.quality[5].use = false;
  const PosLog log = readPosFile(d);
  ASSERT_EQ(log.fixes.size(), 1u);
  EXPECT_EQ(log.left_out_by_quality[5], 1u);
  EXPECT_FALSE(log.has_velocity);
  EXPECT_EQ(log.fixes[0].vel_sigma_ned_mps()[0], d.velocity_sigma_when_absent_mps);
  EXPECT_EQ(log.fixes[0].time_gps_ns(),
            static_cast<std::uint64_t>(2374 * 604800'000'000'000LL + 243258'500'000'000LL));
}

TEST(RtklibPos, MalformedFilesAreErrorsNamingFileLineAndColumn) {
  const std::string header =
      "%  GPST                  latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   "
      "sde(m)   sdu(m)\n";
  auto error = [&](const std::string& name, const std::string& text) {
    PosDescription d;
    d.file = writeText(name, text);
    return errorOf([&] { readPosFile(d); });
  };
  EXPECT_NE(error("q.pos", header + "2374 243258.5 40.1 -105.1 1600.0 9 20 0.01 0.01 0.02\n")
                .find("q.pos line 2: Q: 9 is not an RTKLIB quality 1..6"),
            std::string::npos);
  EXPECT_NE(error("lat.pos", header + "2374 243258.5 4O.1 -105.1 1600.0 1 20 0.01 0.01 0.02\n")
                .find("lat.pos line 2: latitude(deg): '4O.1' is not a number"),
            std::string::npos);
  EXPECT_NE(error("short.pos", header + "2374 243258.5 40.1 -105.1 1600.0 1 20 0.01 0.01\n")
                .find("short.pos line 2: 9 fields, no sdu(m)"),
            std::string::npos);
  EXPECT_NE(
      error("date.pos", header + "2025/13/08 19:34:18.5 40.1 -105.1 1600 1 20 0.01 0.01 0.02\n")
          .find("date.pos line 2: date: '2025/13/08' is not yyyy/mm/dd"),
      std::string::npos);
  EXPECT_NE(error("week.pos", header + "2374 24325B.5 40.1 -105.1 1600 1 20 0.01 0.01 0.02\n")
                .find("week.pos line 2: GPS seconds of week: '24325B.5' is not a number"),
            std::string::npos);
  EXPECT_NE(error("order.pos", header + "2374 243258.5 40.1 -105.1 1600 1 20 0.01 0.01 0.02\n" +
                                   "2374 243258.5 40.1 -105.1 1600 1 20 0.01 0.01 0.02\n")
                .find("order.pos line 3: time stamp not after the previous epoch's"),
            std::string::npos);
  EXPECT_NE(error("utc.pos",
                  "%  UTC  latitude(deg) longitude(deg) height(m) Q ns sdn(m) sde(m) "
                  "sdu(m)\n2374 243258.5 40.1 -105.1 1600 1 20 0.01 0.01 0.02\n")
                .find("navbus reads GPST"),
            std::string::npos);
  EXPECT_NE(error("xyz.pos",
                  "%  GPST  x-ecef(m) y-ecef(m) z-ecef(m) Q ns sdx(m) sdy(m) "
                  "sdz(m)\n2374 243258.5 1 2 3 1 20 0.01 0.01 0.02\n")
                .find("out-solformat = llh"),
            std::string::npos);
  EXPECT_NE(error("none.pos", "2374 243258.5 40.1 -105.1 1600 1 20 0.01 0.01 0.02\n")
                .find("no '%' header line"),
            std::string::npos);
}

TEST(Dataset, ErrorsNameTheKeyAndTheValue) {
  auto error = [&](const std::string& name, const std::string& yaml) {
    const fs::path p = writeText(name, yaml);
    return errorOf([&] { readDatasetDescription(p); });
  };
  const std::string imu = "imu: {file: " + (kReal / "drive_0708/imu_1934.csv").string() +
                          ", time_source: gps_seconds, sample_rate_hz: 100";
  EXPECT_NE(error("typo.yaml", imu + ", acel_unit: g}\n").find("acel_unit"), std::string::npos);
  EXPECT_NE(error("unit.yaml", imu + ", accel_unit: G}\n").find("'G' is not one of g | mg | mps2"),
            std::string::npos);
  EXPECT_NE(error("cols.yaml", imu + ", gyro_columns: [3, 4]}\n").find("needs 3 column numbers"),
            std::string::npos);
  EXPECT_NE(
      error("nofile.yaml", "imu: {file: nowhere.csv, sample_rate_hz: 100}\n").find("imu.file = '"),
      std::string::npos);
  EXPECT_NE(error("notag.yaml", "imu: {file: " + (kReal / "drive_0708/imu_1934.csv").string() +
                                    ", sample_rate_hz: 100}\n")
                .find("imu.time_tag is missing"),
            std::string::npos);
  const std::string pos =
      "gnss_solutions: {file: " + (kReal / "drive_0708/gnss_1934_sf.pos").string();
  EXPECT_NE(error("msl.yaml", pos + ", height: msl}\n").find("geoid_separation_m is missing"),
            std::string::npos);
  EXPECT_NE(error("q.yaml", pos + ", quality: {fixed: {sigma_scale: 2}}}\n").find("fixed"),
            std::string::npos);
  EXPECT_NE(error("empty.yaml", "name: x\n").find("nothing to import"), std::string::npos);
}

TEST(Import, TheDriveBecomesARecordingThatReadsBack) {
  const auto d = readDatasetDescription(kDatasets / "drive_0708.yaml");
  const fs::path out = scratch("drive_recording");
  const ImportReport report = importDataset(d, out);
  EXPECT_EQ(report.imu_increments, 54'859u);
  EXPECT_EQ(report.gnss_fixes, 2197u);
  const auto block_table = records::readCsv(out / "navbus_imu_increment_block.csv");
  const auto blocks = records::parseMessages<navbus::ImuIncrementBlock>(
      block_table, records::messageRowRanges(block_table));
  ASSERT_EQ(blocks.size(), report.imu_blocks);
  std::size_t increments = 0;
  for (const auto& b : blocks) increments += b.increments().size();
  EXPECT_EQ(increments, report.imu_increments);
  const auto fix_table = records::readCsv(out / "navbus_gnss_fix.csv");
  const auto fixes =
      records::parseMessages<navbus::GnssFix>(fix_table, records::messageRowRanges(fix_table));
  ASSERT_EQ(fixes.size(), 2197u);
  const PosLog direct = readPosFile(*d.gnss_solutions);
  EXPECT_EQ(fixes.back().pos_ecef_m(), direct.fixes.back().pos_ecef_m()) << "bit for bit";
}

TEST(RinexObservations, TheWalksPseudorangesAndDopplerBecomeObservationEpochs) {
  const auto d = readDatasetDescription(kDatasets / "walk_0827.yaml");
  ASSERT_TRUE(d.gnss_observations);
  const ObservationLog log = readRinexObservations(*d.gnss_observations);
  // 536 epochs of 7 GPS satellites; 4 of them have broadcast ephemeris in the log.
  EXPECT_EQ(log.epochs_read, 536u);
  ASSERT_EQ(log.epochs.size(), 536u);
  EXPECT_GT(log.no_ephemeris, 1000u);
  EXPECT_FALSE(log.has_iono);
  std::size_t measurements = 0;
  for (const auto& e : log.epochs) measurements += e.satellites().size();
  std::ifstream in(d.gnss_observations->obs);
  const auto rinex = gnss_data::readObservationFile(in, "walk.obs");
  std::size_t in_file = 0;
  for (const auto& e : rinex.epochs) in_file += e.satellites.size();
  EXPECT_EQ(measurements + log.no_ephemeris + log.missing_range + log.below_mask +
                log.other_systems + log.bad_range,
            in_file)
      << "every satellite of every epoch is written or counted";
  // First epoch, G10: C1 20576396.770 m, D1 1064.326 Hz in the RINEX file.
  const auto& first = log.epochs.front();
  EXPECT_EQ(first.time_gps_ns(), static_cast<std::uint64_t>(gpsNs(2025, 8, 28, 17, 30, 39.748)));
  const auto g10 = std::find_if(first.satellites().begin(), first.satellites().end(),
                                [](const auto& s) { return s.sv_id() == 10; });
  ASSERT_NE(g10, first.satellites().end());
  EXPECT_NEAR(g10->pseudorange_rate_mps(), -1064.326 * 299792458.0 / 1575.42e6, 1e-6);
  // The pseudorange as received less the modelled atmosphere (a few metres at most).
  EXPECT_LT(g10->pseudorange_m(), 20576396.770);
  EXPECT_GT(g10->pseudorange_m(), 20576396.770 - 30.0);
  EXPECT_NEAR(
      Eigen::Vector3d(g10->sat_pos_ecef_m()[0], g10->sat_pos_ecef_m()[1], g10->sat_pos_ecef_m()[2])
          .norm(),
      26.56e6, 0.5e6)
      << "a GPS orbit";
  EXPECT_EQ(g10->pseudorange_rate_sigma_mps(), d.gnss_observations->rate_sigma_mps);
  EXPECT_GT(log.single_point.size(), 500u);
}

TEST(RinexObservations, ARampChangesOnlyItsSatelliteAfterItsOnset) {
  auto d = readDatasetDescription(kDatasets / "walk_0827.yaml");
  const ObservationLog clean = readRinexObservations(*d.gnss_observations);
  d.gnss_observations->ramp = PseudorangeRamp{10, 2.0, 40.0};
  const ObservationLog ramped = readRinexObservations(*d.gnss_observations);
  ASSERT_EQ(clean.epochs.size(), ramped.epochs.size());
  const double first_s = 1e-9 * static_cast<double>(clean.epochs.front().time_gps_ns());
  std::uint64_t changed = 0;
  for (std::size_t i = 0; i < clean.epochs.size(); ++i) {
    const double after_onset_s =
        1e-9 * static_cast<double>(clean.epochs[i].time_gps_ns()) - first_s - 40.0;
    for (std::size_t k = 0; k < clean.epochs[i].satellites().size(); ++k) {
      const auto& a = clean.epochs[i].satellites()[k];
      const auto& b = ramped.epochs[i].satellites()[k];
      ASSERT_EQ(a.sv_id(), b.sv_id());
      const double expected = a.sv_id() == 10 && after_onset_s > 0.0 ? 2.0 * after_onset_s : 0.0;
      EXPECT_NEAR(b.pseudorange_m() - a.pseudorange_m(), expected, 1e-6)
          << "G" << a.sv_id() << " epoch " << i;
      changed += expected > 0.0 ? 1 : 0;
    }
  }
  EXPECT_EQ(changed, ramped.injected);
  EXPECT_GT(changed, 300u);
}

TEST(RinexObservations, ErrorsNameTheKeyAndTheFile) {
  const std::string obs = (kReal / "walk_0827/rinex/walk.obs").string();
  const std::string nav = (kReal / "walk_0827/rinex/walk.nav").string();
  auto error = [&](const std::string& name, const std::string& yaml) {
    const fs::path p = writeText(name, yaml);
    return errorOf([&] { readRinexObservations(*readDatasetDescription(p).gnss_observations); });
  };
  EXPECT_NE(error("nonav.yaml", "gnss_observations: {obs: " + obs + "}\n")
                .find("gnss_observations.nav is missing"),
            std::string::npos);
  EXPECT_NE(error("type.yaml",
                  "gnss_observations: {obs: " + obs + ", nav: " + nav + ", range_type: P1}\n")
                .find("no 'P1' observable"),
            std::string::npos);
  EXPECT_NE(error("sigma.yaml",
                  "gnss_observations: {obs: " + obs + ", nav: " + nav + ", rate_sigma_mps: -1}\n")
                .find("rate_sigma_mps"),
            std::string::npos);
  // A malformed observation record names the file and the line.
  std::ifstream in(obs);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = text.find(" 25 08 28 17 30 40.2480000");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 26, " 25 08 28 17 30 4x.2480000");
  const fs::path bad = writeText("bad.obs", text);
  const std::string message =
      error("bad.yaml", "gnss_observations: {obs: " + bad.string() + ", nav: " + nav + "}\n");
  EXPECT_NE(message.find("bad.obs"), std::string::npos) << message;
  EXPECT_NE(message.find("bad.obs:47: field 'second'"), std::string::npos) << message;
}

TEST(Import, AnImuStepChangesOneAxisFromItsOnsetOn) {
  // Ten samples at 100 Hz standing still (1 g up on z); a 0.5 m/s^2 step on x from 0.045 s.
  std::string text;
  for (int k = 0; k < 10; ++k) text += fmt::format("0,0,9.81,0,0,0,{:.2f}\n", 1.4e9 + 0.01 * k);
  DatasetDescription d;
  d.imu = gpsSecondsCsv(writeText("step.csv", text));
  d.imu->step = ImuStep{false, 0, 0.5, 0.045};
  const fs::path out = scratch("step_recording");
  const ImportReport report = importDataset(d, out);
  EXPECT_EQ(report.imu_samples_injected, 5u);  // 0.05 .. 0.09 s
  EXPECT_EQ(report.imu_step_onset_gps_ns,
            readImuCsv(*d.imu).samples.front().time_gps_ns + 45'000'000);
  EXPECT_NE(report.text.find("an accelerometer step of 0.5 m/s^2 on sensor axis x"),
            std::string::npos)
      << report.text;
  const auto table = records::readCsv(out / "navbus_imu_increment_block.csv");
  const auto blocks =
      records::parseMessages<navbus::ImuIncrementBlock>(table, records::messageRowRanges(table));
  std::vector<double> dv_x;
  for (const auto& b : blocks)
    for (const auto& inc : b.increments()) dv_x.push_back(inc.delta_vel_b_mps()[0]);
  ASSERT_EQ(dv_x.size(), 9u);
  // Trapezoidal increments: none before the onset, half a step across it, a full one after
  // (the intervals are 10 ms to the 128 ns a double keeps of a GPS time of 1.4e9 s).
  EXPECT_EQ(dv_x[3], 0.0);
  EXPECT_NEAR(dv_x[4], 0.5 * 0.5 * 0.01, 1e-7);
  EXPECT_NEAR(dv_x[8], 0.5 * 0.01, 1e-7);
  // The onset must fall inside the log, and the error says where the log ends.
  d.imu->step->onset_after_start_s = 2.0;
  const std::string e = errorOf([&] { importDataset(d, scratch("late_step")); });
  EXPECT_NE(e.find("IMU step onset 2 s after the first sample is beyond the log's last sample "
                   "(0.090 s)"),
            std::string::npos)
      << e;
}
