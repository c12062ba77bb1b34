// The recordings' text forms: CSV rows per message and numbers that round-trip.
#include <gtest/gtest.h>

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
