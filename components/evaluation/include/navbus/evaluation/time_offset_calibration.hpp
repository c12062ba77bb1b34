// `navbus calibrate time-offset`: the IMU's and the GNSS velocity's time offsets against the
// GNSS positions, from the filter's own innovations. A logger that stamps the IMU late by dt
// makes the filter compare each fix with the state dt earlier: the position innovation grows
// with v dt, and in turns (where the velocity's direction changes) it cannot be absorbed by a
// bias. A receiver whose velocity lags its position by tau (a velocity from differenced
// positions, a filtered Doppler solution) makes the velocity innovation grow with the
// acceleration a tau, centripetal in turns. So, over a whole log with GNSS never withheld (the
// outage score plays no part):
//  1. the IMU offset (added to inputs.imu.time_offset_s) that minimizes the mean normalized
//     innovation squared (NIS) of the fixes' position rows;
//  2. with it, the velocity offset (inputs.gnss_fix.velocity_time_offset_s, from 0 back) that
//     minimizes the mean NIS of the velocity rows.
// The two stages alternate (o.rounds, coordinate descent). The filter runs once per candidate
// of each grid, and a parabola through the smallest mean
// NIS and its two neighbours refines it.
#pragma once

#include <string>
#include <vector>

#include "navbus/evaluation/recording_runner.hpp"

namespace navbus::evaluation {

struct OffsetTrial {
  double offset_s{0.0};   ///< the offset of the run [s]
  double mean_nis{0.0};   ///< mean NIS of the rows the search minimizes
  double other_nis{0.0};  ///< mean NIS of the fixes' other rows (velocity, or position)
  std::uint64_t rows{0};
  std::uint64_t epochs_tested{0}, epochs_inconsistent{0};
};

struct OffsetSearch {
  std::vector<OffsetTrial> trials;  ///< in offset order
  std::size_t best{0};              ///< index of the smallest mean NIS
  double refined_s{0.0};            ///< the parabola's minimum (the grid's best at an edge)
  bool at_edge{false};              ///< the smallest mean NIS lies at the grid's edge
};

struct Grid {
  double from_s{0.0}, to_s{0.0}, step_s{0.01};
};

/// Stage 1: inputs.imu.time_offset_s over the configured one plus each grid offset, scored by
/// the position rows. Throws bus::ConfigError for a bad grid or a run without fixes fused.
OffsetSearch searchImuTimeOffset(const RecordingSetup& base, const Grid& grid);
/// Stage 2: inputs.gnss_fix.velocity_time_offset_s over the grid (each <= 0), scored by the
/// velocity rows.
OffsetSearch searchVelocityTimeOffset(const RecordingSetup& base, const Grid& grid);

struct TimeOffsetOptions {
  std::string dataset;
  std::string filter;
  std::string out_dir;  ///< the imported recording and time_offset.csv
  Grid imu{-0.3, 0.3, 0.02};
  Grid velocity{-0.3, 0.0, 0.02};
  int rounds{2};  ///< stage 1 and 2 alternated this often
};

int runTimeOffsetCommand(const TimeOffsetOptions& o);

}  // namespace navbus::evaluation
