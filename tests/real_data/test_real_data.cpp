// Real GPS data through navbus's GNSS path: the RINEX readers, single point positioning
// against RTKLIB's rnx2rtkp on the same files, and the GLR on the static receiver filter.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "navbus/bus/config.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/evaluation/real_data.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/gnss_data/rinex2.hpp"
#include "test_paths.hpp"

namespace nb = navbus;
using nb::gnss_data::readNavigationFile;
using nb::gnss_data::readObservationFile;

namespace {

const std::string kObs = std::string(navbus::test_paths::rinexDir()) + "/07590920.05o";
const std::string kNav = std::string(navbus::test_paths::rinexDir()) + "/07590920.05n";
const Eigen::Vector3d kReference(-3976219.5082, 3382372.5671, 3652512.9849);

nb::evaluation::RealDataSetup loadSetup(bool with_fault_manager) {
  nb::evaluation::RealDataSetup s;
  std::ifstream o(kObs), n(kNav);
  s.obs = readObservationFile(o, kObs);
  s.nav = readNavigationFile(n, kNav);
  s.reference_ecef_m = kReference;
  if (with_fault_manager) {
    s.fault_manager = nb::fault_manager::parseFaultManagerConfig(nb::bus::loadYamlFile(
        std::string(navbus::test_paths::configDir()) + "/fault_manager_static.yaml"));
  }
  return s;
}

struct RtklibFix {
  double gps_s;
  Eigen::Vector3d ecef;
};

/// rnx2rtkp single point (broadcast ionosphere, Saastamoinen, 10 deg mask, ECEF output).
std::vector<RtklibFix> runRtklib() {
  const std::string rnx2rtkp = navbus::test_paths::rnx2rtkp();
  if (rnx2rtkp.empty() || rnx2rtkp.find("NOTFOUND") != std::string::npos) {
    ADD_FAILURE() << "rnx2rtkp not found: install Debian's rtklib (scripts/install-deps.sh)";
    return {};
  }
  const std::string work = navbus::test_paths::workDir();
  std::filesystem::create_directories(work);
  std::ofstream(work + "/spp.conf") << "pos1-posmode =single\npos1-ionoopt =brdc\n"
                                       "pos1-tropopt =saas\npos1-elmask =10\n"
                                       "out-solformat =xyz\nout-timesys =gpst\n";
  const std::string cmd = rnx2rtkp + " -k " + work + "/spp.conf -o " + work + "/rtklib.pos " +
                          kObs + " " + kNav + " > " + work + "/rtklib.log 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::vector<RtklibFix> fixes;
  std::ifstream in(work + "/rtklib.pos");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '%') continue;
    int y, mo, d, h, mi;
    double sec, x, yy, z;
    if (std::sscanf(line.c_str(), "%d/%d/%d %d:%d:%lf %lf %lf %lf", &y, &mo, &d, &h, &mi, &sec, &x,
                    &yy, &z) != 9)
      continue;
    fixes.push_back({nb::gnss_data::gpsSecondsFromCalendar(y, mo, d, h, mi, sec), {x, yy, z}});
  }
  return fixes;
}

}  // namespace

TEST(GpsTime, CalendarToGpsSeconds) {
  EXPECT_EQ(nb::gnss_data::gpsSecondsFromCalendar(1980, 1, 6, 0, 0, 0.0), 0.0);
  // RTKLIB prints the first epoch of the test data as week 1316, 518400 s.
  EXPECT_EQ(nb::gnss_data::gpsSecondsFromCalendar(2005, 4, 2, 0, 0, 0.0),
            1316 * 604800.0 + 518400.0);
  EXPECT_EQ(nb::gnss_data::gpsSecondsFromCalendar(2000, 3, 1, 0, 0, 0.0) -
                nb::gnss_data::gpsSecondsFromCalendar(2000, 2, 28, 0, 0, 0.0),
            2 * 86400.0);  // 2000 is a leap year
}

TEST(Rinex, ReadsTheStationHour) {
  const nb::evaluation::RealDataSetup s = loadSetup(false);
  EXPECT_EQ(s.obs.marker, "0759");
  ASSERT_EQ(s.obs.types, (std::vector<std::string>{"L1", "C1", "L2", "P2"}));
  EXPECT_EQ(s.obs.epochs.size(), 120u);
  EXPECT_NEAR((s.obs.approx_position_ecef_m - kReference).norm(), 0.0, 1e-9);
  const auto& first = s.obs.epochs.front();
  ASSERT_EQ(first.satellites.size(), 8u);
  EXPECT_EQ(first.satellites[0].prn, 3);
  EXPECT_DOUBLE_EQ(*first.satellites[0].values[1], 24767686.375);
  EXPECT_TRUE(s.nav.has_iono);
  EXPECT_DOUBLE_EQ(s.nav.iono.alpha[0], 1.1180e-08);
  EXPECT_DOUBLE_EQ(s.nav.iono.beta[3], -1.3110e+05);
  ASSERT_FALSE(s.nav.ephemerides.empty());
  const auto& e = s.nav.ephemerides.front();
  EXPECT_EQ(e.sv_id, 1);
  EXPECT_DOUBLE_EQ(e.af0_s, 3.966595977540e-04);
  EXPECT_DOUBLE_EQ(e.sqrt_a_sqrtm, 5.153636478420e+03);
  EXPECT_DOUBLE_EQ(e.toe_s, 1316 * 604800.0 + 5.256e5);
  EXPECT_DOUBLE_EQ(e.tgd_s, -3.259629011150e-09);
}

TEST(Rinex, MalformedFieldsNameLineAndField) {
  std::ifstream n(kNav);
  std::stringstream text;
  text << n.rdbuf();
  std::string s = text.str();
  const auto pos = s.find("5.153636478420D+03");  // sqrt(A) of the first record
  s.replace(pos, 18, "5.15363647x420D+03");
  std::istringstream bad(s);
  try {
    readNavigationFile(bad, "bad.05n");
    FAIL() << "no error";
  } catch (const nb::gnss_data::RinexError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bad.05n:15:"), std::string::npos) << what;
    EXPECT_NE(what.find("sqrt(A)"), std::string::npos) << what;
    EXPECT_NE(what.find("5.15363647x420D+03"), std::string::npos) << what;
  }
  std::istringstream not_rinex("hello\n");
  EXPECT_THROW(readObservationFile(not_rinex, "x"), nb::gnss_data::RinexError);
}

// navbus's single point fixes against RTKLIB on the same files: same models (IS-GPS-200
// orbit and clock, Klobuchar, Saastamoinen, elevation-dependent weights), same answer.
TEST(SinglePoint, MatchesRtklibEpochByEpoch) {
  const std::vector<RtklibFix> rtk = runRtklib();
  ASSERT_EQ(rtk.size(), 120u);
  const nb::evaluation::RealDataResult r = nb::evaluation::runRealData(loadSetup(false));
  ASSERT_EQ(r.epochs.size(), 120u);
  EXPECT_EQ(r.fixes, 120u);
  double max_diff = 0.0, sum_sq = 0.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < rtk.size(); ++i) {
    ASSERT_NEAR(static_cast<double>(r.epochs[i].time_ns) * 1e-9, rtk[i].gps_s, 0.01);
    max_diff = std::max(max_diff, (r.epochs[i].fix_ecef_m - rtk[i].ecef).norm());
    const Eigen::Vector3d err = r.epochs[i].fix_ecef_m - kReference;
    mean += err / 120.0;
    sum_sq += err.squaredNorm();
  }
  std::printf(
      "navbus vs rnx2rtkp: largest difference %.4f m; navbus 3D RMS %.3f m, mean ECEF "
      "(%.3f, %.3f, %.3f) m\n",
      max_diff, std::sqrt(sum_sq / 120.0), mean.x(), mean.y(), mean.z());
  EXPECT_LT(max_diff, 0.01);
  EXPECT_NEAR(std::sqrt(sum_sq / 120.0), 1.21, 0.01);  // RTKLIB's figure on these files
}

TEST(RealData, CleanHourHasNoFalseAlarm) {
  const nb::evaluation::RealDataSetup s = loadSetup(true);
  const nb::evaluation::RealDataResult r = nb::evaluation::runRealData(s);
  std::printf("clean hour: largest GLR statistic %.2f (h %.3f), final filter error %.2f m\n",
              r.max_glr_statistic, s.fault_manager->glr.glr.threshold,
              r.epochs.back().filter_error_ned_m.norm());
  EXPECT_TRUE(r.decisions.empty());
  EXPECT_TRUE(r.commands.empty());
  EXPECT_GT(r.max_glr_statistic, 0.0);  // the GLR did run on every epoch
  EXPECT_LT(r.max_glr_statistic, s.fault_manager->glr.glr.threshold);
  EXPECT_LT(r.epochs.back().filter_error_ned_m.norm(), 2.0);
}

// A 10 m/s ramp from 1800 s on each satellite the filter uses then: detected at the first
// epoch it shows (1830 s: 300 m), that satellite isolated and excluded, the filter re-run
// from the onset without it and back near the reference.
TEST(RealData, InjectedRampIsDetectedAndTheSatelliteIsolated) {
  for (int sv : {7, 11, 19, 20, 24, 28}) {
    nb::evaluation::RealDataSetup s = loadSetup(true);
    s.ramp = nb::evaluation::RampInjection{sv, 10.0, 1800.0};
    const nb::evaluation::RealDataResult r = nb::evaluation::runRealData(s);
    ASSERT_EQ(r.decisions.size(), 1u) << "sv " << sv;
    const nb::FaultDecision& d = r.decisions.front();
    const double start = s.obs.epochs.front().time_s;
    EXPECT_EQ(d.source(), nb::SOURCE_SATELLITE) << "sv " << sv;
    EXPECT_EQ(d.sv_id(), sv);
    EXPECT_FALSE(d.ambiguous()) << "sv " << sv;
    EXPECT_NEAR(static_cast<double>(d.time_gps_ns()) * 1e-9 - start, 1830.0, 0.01)
        << "sv " << sv;  // time tags carry ms
    ASSERT_EQ(r.commands.size(), 1u) << "sv " << sv;
    EXPECT_EQ(r.commands.front().kind(), nb::CMD_EXCLUDE_SATELLITE);
    EXPECT_EQ(r.commands.front().sv_id(), sv);
    EXPECT_EQ(r.reprocessings, 1u);
    EXPECT_LT(r.epochs.back().filter_error_ned_m.norm(), 2.0) << "sv " << sv;
  }
}

// The detector's sensitivity on real data: a slow 0.1 m/s ramp (3 m per epoch) is found too,
// later.
TEST(RealData, SlowRampIsDetectedLater) {
  nb::evaluation::RealDataSetup s = loadSetup(true);
  s.ramp = nb::evaluation::RampInjection{28, 0.1, 1800.0};
  const nb::evaluation::RealDataResult r = nb::evaluation::runRealData(s);
  ASSERT_EQ(r.decisions.size(), 1u);
  EXPECT_EQ(r.decisions.front().sv_id(), 28);
  const double delay = static_cast<double>(r.decisions.front().time_gps_ns()) * 1e-9 -
                       s.obs.epochs.front().time_s - 1800.0;
  std::printf("0.1 m/s ramp on sv 28: detected %.0f s after its onset\n", delay);
  EXPECT_GT(delay, 30.0);
  EXPECT_LT(delay, 600.0);
}

// RINEX 3: the walk's raw u-blox log converted by convbin with its default output (RINEX 3.04,
// mixed GPS, Galileo and SBAS) reads as the shipped RINEX 2.11 conversion does: the same GPS
// epochs, pseudoranges and Doppler (C1C/D1C against C1/D1), the same GPS ephemerides; the
// other systems' satellites and records counted.
TEST(Rinex3, TheWalksConvbinDefaultOutputReadsAsItsRinex2) {
  const std::string convbin = navbus::test_paths::convbin();
  ASSERT_FALSE(convbin.empty() || convbin.find("NOTFOUND") != std::string::npos)
      << "convbin not found: install Debian's rtklib (scripts/install-deps.sh)";
  const std::string work = std::string(navbus::test_paths::workDir()) + "/rinex3";
  std::filesystem::create_directories(work);
  const std::string real = std::string(navbus::test_paths::realDir()) + "/walk_0827";
  const std::string command = convbin + " -r ubx -od -os -o " + work + "/walk.obs -n " + work +
                              "/walk.nav " + real + "/gnss_1730.ubx > " + work +
                              "/convbin.log 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  auto read = [](const std::string& file, auto reader) {
    std::ifstream in(file);
    return reader(in, file);
  };
  const auto obs3 = read(work + "/walk.obs", &nb::gnss_data::readObservationFile);
  const auto obs2 = read(real + "/rinex/walk.obs", &nb::gnss_data::readObservationFile);
  const auto nav3 = read(work + "/walk.nav", &nb::gnss_data::readNavigationFile);
  const auto nav2 = read(real + "/rinex/walk.nav", &nb::gnss_data::readNavigationFile);
  EXPECT_EQ(obs3.major_version, 3);
  EXPECT_EQ(obs3.system_types.size(), 3u) << "G, E and S";
  ASSERT_EQ(obs3.epochs.size(), obs2.epochs.size());
  const int c3 = obs3.typeIndex("C1C"), d3 = obs3.typeIndex("D1C");
  const int c2 = obs2.typeIndex("C1"), d2 = obs2.typeIndex("D1");
  ASSERT_GE(c3, 0);
  ASSERT_GE(d3, 0);
  std::size_t compared = 0, other_systems = 0;
  for (std::size_t i = 0; i < obs3.epochs.size(); ++i) {
    ASSERT_DOUBLE_EQ(obs3.epochs[i].time_s, obs2.epochs[i].time_s) << i;
    for (const auto& s3 : obs3.epochs[i].satellites) {
      if (s3.system != 'G') {
        ++other_systems;
        continue;
      }
      for (const auto& s2 : obs2.epochs[i].satellites) {
        if (s2.prn != s3.prn) continue;
        const auto& a = s3.values[static_cast<std::size_t>(c3)];
        const auto& b = s2.values[static_cast<std::size_t>(c2)];
        ASSERT_EQ(a.has_value(), b.has_value()) << "epoch " << i << " G" << s3.prn;
        if (a) {
          EXPECT_DOUBLE_EQ(*a, *b);
        }
        const auto& da = s3.values[static_cast<std::size_t>(d3)];
        const auto& db = s2.values[static_cast<std::size_t>(d2)];
        if (da && db) {
          EXPECT_DOUBLE_EQ(*da, *db);
        }
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 3000u);
  EXPECT_GT(other_systems, 0u);
  ASSERT_EQ(nav3.ephemerides.size(), nav2.ephemerides.size());
  for (std::size_t i = 0; i < nav3.ephemerides.size(); ++i) {
    EXPECT_EQ(nav3.ephemerides[i].sv_id, nav2.ephemerides[i].sv_id);
    EXPECT_EQ(nav3.ephemerides[i].toe_s, nav2.ephemerides[i].toe_s);
    EXPECT_EQ(nav3.ephemerides[i].toc_s, nav2.ephemerides[i].toc_s);
    EXPECT_EQ(nav3.ephemerides[i].sqrt_a_sqrtm, nav2.ephemerides[i].sqrt_a_sqrtm);
    EXPECT_EQ(nav3.ephemerides[i].af0_s, nav2.ephemerides[i].af0_s);
  }
  EXPECT_GT(nav3.other_systems, 0u) << "Galileo records";
  std::printf(
      "RINEX 3: %zu epochs, %zu GPS measurements equal to RINEX 2's, %zu of other "
      "systems; %zu GPS ephemerides equal, %llu other records\n",
      obs3.epochs.size(), compared, other_systems, nav3.ephemerides.size(),
      static_cast<unsigned long long>(nav3.other_systems));
  std::filesystem::remove_all(work);
}
