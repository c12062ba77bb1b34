/* A Cyclone DDS application on the navbus bus, built from the same IDL with Cyclone's idlc:
 * it publishes IMU increments that navbus-filter (Fast DDS) must accept, and reads the
 * navigation solution navbus-filter publishes. Exit 0 when both directions worked.
 * Usage: cyclone_peer DOMAIN SENSOR_ID N_INCREMENTS */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "Imu.h"
#include "Navigation.h"
#include "dds/dds.h"

#define CHECK(x, what)                                                           \
  do {                                                                           \
    if ((x) < 0) {                                                               \
      fprintf(stderr, "cyclone_peer: %s failed: %s\n", what, dds_strretcode(x)); \
      return 1;                                                                  \
    }                                                                            \
  } while (0)

static const double kDeg = M_PI / 180.0;

/* WGS84 normal gravity (Somigliana), same site as the filter's configuration. */
static double normal_gravity(double lat) {
  const double s2 = sin(lat) * sin(lat);
  return 9.7803253359 * (1.0 + 0.00193185265241 * s2) / sqrt(1.0 - 0.00669437999013 * s2);
}

int main(int argc, char** argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: cyclone_peer DOMAIN SENSOR_ID N_INCREMENTS\n");
    return 2;
  }
  const dds_domainid_t domain = (dds_domainid_t)atoi(argv[1]);
  const uint32_t sensor_id = (uint32_t)atoi(argv[2]);
  const int n = atoi(argv[3]);

  dds_entity_t participant = dds_create_participant(domain, NULL, NULL);
  CHECK(participant, "create participant");

  /* Writer QoS compatible with navbus_sensor_reader: reliable, keep all, automatic liveliness
   * with a lease no longer than the reader's 1 s. */
  dds_qos_t* wqos = dds_create_qos();
  dds_qset_reliability(wqos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_history(wqos, DDS_HISTORY_KEEP_ALL, 0);
  dds_qset_liveliness(wqos, DDS_LIVELINESS_AUTOMATIC, DDS_SECS(1));
  dds_entity_t imu_topic =
      dds_create_topic(participant, &navbus_ImuIncrement_desc, "navbus/imu/increment", NULL, NULL);
  CHECK(imu_topic, "create imu topic");
  dds_entity_t writer = dds_create_writer(participant, imu_topic, wqos, NULL);
  CHECK(writer, "create writer");

  /* Reader QoS compatible with navbus_solution_writer: reliable, transient local, keep all. */
  dds_qos_t* rqos = dds_create_qos();
  dds_qset_reliability(rqos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(rqos, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(rqos, DDS_HISTORY_KEEP_ALL, 0);
  dds_entity_t sol_topic = dds_create_topic(participant, &navbus_NavigationSolution_desc,
                                            "navbus/nav/solution", NULL, NULL);
  CHECK(sol_topic, "create solution topic");
  dds_entity_t reader = dds_create_reader(participant, sol_topic, rqos, NULL);
  CHECK(reader, "create reader");

  /* Wait for navbus-filter's IMU reader (Fast DDS) to match. */
  dds_publication_matched_status_t pm = {0};
  for (int i = 0; i < 400 && pm.current_count == 0; ++i) {
    dds_get_publication_matched_status(writer, &pm);
    dds_sleepfor(DDS_MSECS(50));
  }
  if (pm.current_count == 0) {
    fprintf(stderr, "cyclone_peer: navbus-filter's IMU reader never matched\n");
    return 1;
  }

  /* A level vehicle at rest heading north at 36.5 N: exact increments over 10 ms. */
  const double lat = 36.5 * kDeg;
  const double dt = 0.01;
  const double omega = 7.292115e-5;
  const uint64_t t0 = 1400000000000000000ULL;
  for (int k = 1; k <= n; ++k) {
    navbus_ImuIncrement m = {0};
    m.sensor_id = sensor_id;
    m.seq = (uint64_t)k;
    m.time_gps_ns = t0 + (uint64_t)k * 10000000ULL;
    m.interval_ns = 10000000U;
    m.delta_vel_b_mps[2] = -normal_gravity(lat) * dt;
    m.delta_angle_b_rad[0] = omega * cos(lat) * dt;
    m.delta_angle_b_rad[2] = -omega * sin(lat) * dt;
    CHECK(dds_write(writer, &m), "write increment");
    dds_sleepfor(DDS_MSECS(1));
  }

  /* Read the solutions navbus-filter publishes from our increments. */
  int solutions = 0, bad = 0;
  uint64_t last_time = 0;
  for (int i = 0; i < 200 && solutions < n / 10; ++i) {
    navbus_NavigationSolution buf[16];
    void* samples[16];
    dds_sample_info_t infos[16];
    for (int j = 0; j < 16; ++j) samples[j] = &buf[j];
    const dds_return_t got = dds_take(reader, samples, infos, 16, 16);
    CHECK(got, "take solutions");
    for (int j = 0; j < got; ++j) {
      if (!infos[j].valid_data) continue;
      ++solutions;
      last_time = buf[j].time_gps_ns;
      const double dlat_m = (buf[j].latitude_rad - lat) * 6.36e6;
      if (!isfinite(buf[j].latitude_rad) || fabs(dlat_m) > 1.0 ||
          fabs(buf[j].height_m - 100.0) > 1.0 || buf[j].mode != navbus_MODE_INERTIAL_ONLY) {
        ++bad;
      }
    }
    dds_sleepfor(DDS_MSECS(50));
  }
  printf(
      "cyclone_peer: wrote %d increments, read %d solutions from navbus-filter (%d out of bounds), "
      "last at GPS %llu ns\n",
      n, solutions, bad, (unsigned long long)last_time);
  dds_delete(participant);
  dds_delete_qos(wqos);
  dds_delete_qos(rqos);
  return (solutions >= n / 10 && bad == 0) ? 0 : 1;
}
