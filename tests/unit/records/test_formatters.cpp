// The recordings' text forms: CSV rows per message and numbers that round-trip.
#include <gtest/gtest.h>

#include <filesystem>
#include <vector>

#include "navbus/records/csv_messages.hpp"
#include "navbus/records/formatters.hpp"

TEST(Formatters, CsvHasOneRowPerSatelliteAndRoundTripsDoubles) {
  navbus::GnssObservationEpoch e;
  e.receiver_id(3);
  e.time_gps_ns(42);
  for (int sv : {4, 9}) {
    navbus::GnssSatelliteMeasurement m;
    m.sv_id(static_cast<std::uint16_t>(sv));
    m.pseudorange_m(20000000.125);
    e.satellites().push_back(m);
  }
  const std::string header = navbus::records::csvHeader<navbus::GnssObservationEpoch>();
  EXPECT_EQ(
      header.rfind("receiver_id,seq,time_gps_ns,satellites.sv_id,satellites.pseudorange_m", 0), 0u);
  const auto rows = navbus::records::csvRows(e);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1].rfind("3,0,42,9,20000000.125", 0), 0u);
  navbus::Health h;
  h.participant("navbus-filter");
  h.state(navbus::STATE_DEGRADED);
  const auto hr = navbus::records::csvRows(h);
  ASSERT_EQ(hr.size(), 1u);  // no inputs: one row with empty input cells
  EXPECT_EQ(hr[0].rfind("navbus-filter,0,0,DEGRADED,0", 0), 0u);
  // Shortest text that reads back to the same bits.
  for (const double v :
       {0.1 + 0.2, 0.00980665, 9.80665 / 1000.0, 1e-300, -3000.0, 6378137.0, 1.1309733552923256}) {
    const std::string text = navbus::records::formatNumber(v);
    EXPECT_EQ(std::stod(text), v) << text;
  }
  EXPECT_EQ(navbus::records::formatNumber(0.00980665), "0.00980665");
  EXPECT_EQ(navbus::records::formatNumber(0.1 + 0.2), "0.30000000000000004");
  EXPECT_EQ(navbus::records::formatNumber(3000.0), "3000");
}

// A block of epochs (fast pacing) has a sequence of structs inside each element: a row per
// satellite of each epoch, with the epoch's cells repeated, that reads back to the same block.
TEST(Formatters, ABlockOfEpochsHasARowPerSatelliteAndReadsBack) {
  navbus::GnssObservationEpochBlock block;
  block.receiver_id(3);
  block.seq(7);
  for (int k = 0; k < 3; ++k) {
    navbus::GnssObservationEpoch e;
    e.receiver_id(3);
    e.seq(static_cast<std::uint64_t>(10 + k));
    e.time_gps_ns(static_cast<std::uint64_t>(100 * k));
    // Epoch 1 has no satellite: one row, its satellite cells empty.
    for (int sv = 0; sv < (k == 1 ? 0 : 2 + k); ++sv) {
      navbus::GnssSatelliteMeasurement m;
      m.sv_id(static_cast<std::uint16_t>(sv + 1));
      m.pseudorange_m(20000000.125 + sv);
      m.valid(true);
      e.satellites().push_back(m);
    }
    block.epochs().push_back(e);
  }
  const std::string header = navbus::records::csvHeader<navbus::GnssObservationEpochBlock>();
  EXPECT_EQ(header.rfind("receiver_id,seq,epochs.receiver_id,epochs.seq,epochs.time_gps_ns,"
                         "epochs.satellites.sv_id,epochs.satellites.pseudorange_m",
                         0),
            0u)
      << header;
  const auto rows = navbus::records::csvRows(block);
  ASSERT_EQ(rows.size(), 2u + 1u + 4u);
  EXPECT_EQ(rows[2].rfind("3,7,3,11,100,,", 0), 0u) << rows[2];
  EXPECT_EQ(rows[6].rfind("3,7,3,12,200,4,20000003.125", 0), 0u) << rows[6];

  // Two blocks in one file read back as they were written.
  navbus::GnssObservationEpochBlock second = block;
  second.seq(8);
  second.epochs().erase(second.epochs().begin());
  const auto path = std::filesystem::temp_directory_path() / "navbus_test_epoch_blocks.csv";
  ASSERT_TRUE(navbus::records::writeCsvFile(path.string(), std::vector{block, second}));
  const navbus::records::CsvTable table = navbus::records::readCsv(path);
  std::filesystem::remove(path);
  const auto read = navbus::records::parseMessages<navbus::GnssObservationEpochBlock>(
      table, navbus::records::messageRowRanges(table));
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0], block);
  EXPECT_EQ(read[1], second);
}
