#include "navbus/nav_filter/pipeline_summary.hpp"

#include <sstream>

#include <fmt/format.h>

#include "navbus/core/math/units.hpp"
#include "navbus/nav_filter/solution_messages.hpp"

namespace navbus::nav_filter {

namespace {

void describeCounts(const PipelineView& v, std::ostringstream& out) {
  const core::EngineCounters& n = v.engine.counters();
  const CommandCounters& k = v.commands;
  const PipelineCounters& p = v.counters;
  out << "increments integrated " << n.imu_used << " refused by the engine " << n.imu_refused
      << ", solutions published " << v.solutions_published << ", inertial gaps " << n.imu_gaps
      << " (propagated across " << n.gaps_bridged << ")"
      << ", consistency: epochs tested " << v.engine.consistency().counters().epochs_tested
      << " inconsistent " << v.engine.consistency().counters().epochs_inconsistent << " alarms "
      << v.engine.consistency().counters().alarms << " (IMU bias sigmas raised at "
      << n.bias_inflations << "), mean NIS of the fixes' position rows "
      << fmt::format("{:.3f}", n.fix_position_nis.mean()) << " velocity rows "
      << fmt::format("{:.3f}", n.fix_velocity_nis.mean()) << " (velocities older than the history "
      << n.fix_velocities_beyond_history << "), re-initialisations asked "
      << n.reinitialisations_asked << " done " << n.reinitialisations_done << ", GNSS epochs fused "
      << n.gnss_epochs_fused << ", fixes fused " << n.fixes_fused
      << ", star-tracker attitudes fused " << n.star_fused << ", ZUPTs " << n.zero_velocity_updates
      << ", NHC updates " << n.nonholonomic_updates
      << ", pseudoranges without an error state (every state taken) "
      << v.engine.pseudorangesWithoutErrorState() << ", satellites beyond an epoch's capacity "
      << n.epoch_satellites_dropped << ", further receivers' clocks started "
      << n.receiver_clocks_started << ", rows gated " << n.rows_gated << ", stage switches "
      << n.stage_switches << ", decisions seen " << p.decisions_seen << ", commands applied "
      << k.applied << " refused " << k.refused << " (unauthorized issuer " << k.unauthorized
      << ", issuer not the writer's identity " << k.impersonated << ", stale " << k.stale
      << ") late " << k.late << ", re-learn sigmas clamped to the compensation limit "
      << k.relearn_clamped << ", sequencer timeouts " << v.sequencer_timeouts << ", pending "
      << v.pending << ", merge buffer grown " << v.merge_grown << ", recoveries from onset "
      << p.onset_recoveries << " (onset beyond history " << p.onset_beyond_history << ")"
      << ", late samples merged by rewinding " << p.late_merged << " (rewinds " << p.rewinds << ")"
      << ", solutions published not trustworthy " << p.solutions_untrusted;
}

/// Each stream that fed the adaptive noise: its scale now, the largest applied, and how many
/// of its epochs were fused with a scale other than 1 and at the ceiling.
std::string describeAdaptiveNoise(const core::NavigationEngine& engine) {
  std::string out =
      "adaptive noise (scale on R now / largest; epochs scaled, at the ceiling, of all):";
  for (int i = 0; i < core::kNoiseStreams; ++i) {
    const auto s = static_cast<core::NoiseStream>(i);
    const core::NoiseScaleEstimator& e = engine.noiseScale(s);
    const core::NoiseScaleCounters& c = e.counters();
    if (c.epochs == 0) continue;
    out += fmt::format(" {} {:.2f} / {:.2f}; {}, {}, of {}", core::noiseStreamName(s), e.scale(),
                       c.max_scale, c.epochs_scaled, c.epochs_at_ceiling, c.epochs);
  }
  return out;
}

/// The adaptive process noise: its scale now, the largest applied, the epochs propagated into
/// with a scale other than 1 and at the ceiling, and the rows' weight in the estimate now.
std::string describeAdaptiveProcessNoise(const core::NavigationEngine& engine) {
  const core::ProcessNoiseScaleEstimator& e = engine.processNoiseScale();
  const core::ProcessNoiseScaleCounters& c = e.counters();
  return fmt::format(
      "adaptive process noise (scale on Q now / largest; epochs scaled, at the ceiling, of all; "
      "information in rows now): {:.2f} / {:.2f}; {}, {}, of {}; {:.1f}",
      e.scale(), c.max_scale, c.epochs_scaled, c.epochs_at_ceiling, c.epochs, e.informationRows());
}

/// The mounting misalignment the filter estimated, with its 1 sigma, roll / pitch / yaw.
std::string describeMounting(const core::NavigationEngine& engine) {
  const Eigen::Vector3d mu_deg = engine.mountingMisalignment() / units::kDeg;
  const Eigen::Vector3d sigma_deg = engine.covariance()
                                        .diagonal()
                                        .segment<3>(core::layout::kMountingMisalignment.index)
                                        .cwiseSqrt() /
                                    units::kDeg;
  return fmt::format(
      "mounting misalignment (roll, pitch, yaw) {:.3f} / {:.3f} / {:.3f} deg (1 sigma {:.3f} / "
      "{:.3f} / {:.3f})",
      mu_deg.x(), mu_deg.y(), mu_deg.z(), sigma_deg.x(), sigma_deg.y(), sigma_deg.z());
}

void describeOptional(const PipelineView& v, std::ostringstream& out) {
  const PipelineCounters& p = v.counters;
  if (p.stalls > 0) {
    out << ", stalls of the filter process " << p.stalls << " (longest "
        << 1e-9 * static_cast<double>(p.longest_stall_ns) << " s)";
  }
  if (v.progress_reports > 0 || v.judgement_timeouts > 0) {
    out << ", fault manager's progress reports " << v.progress_reports << " (before their command "
        << v.progress_held << "), judgements waited for beyond the budget " << v.judgement_timeouts;
  }
  if (v.flags.monitorLosses() > 0) {
    out << ", fault monitor found not alive " << v.flags.monitorLosses() << " time(s)"
        << (v.flags.faultMonitorAlive() ? "" : " (still not)");
  }
  if (v.config.engine.adaptive_noise.enabled) out << ", " << describeAdaptiveNoise(v.engine);
  if (v.config.engine.adaptive_process_noise.enabled)
    out << ", " << describeAdaptiveProcessNoise(v.engine);
  if (v.config.engine.start == core::StartSource::kAligned)
    out << ", " << describeAlignment(v.engine);
  if (v.engine.initialized() && v.engine.modelsMountingMisalignment())
    out << ", " << describeMounting(v.engine);
  if (v.config.engine.integrity.enabled) {
    out << ", protection-level epochs " << v.engine.protectionLevelEpochs() << " refused "
        << v.engine.protectionLevelEpochsRefused() << " with a fault declared "
        << v.engine.protectionLevelDetections();
  }
  if (v.config.low_latency_output) {
    const core::OutputPredictorCounters& l = v.low_latency;
    out << ", low-latency outputs " << l.outputs << " (increments not after the anchor "
        << l.before_anchor << ", out of order " << l.not_after_previous << ", gaps " << l.gaps
        << ", beyond the buffer " << l.overflow << ")";
  }
  if (p.new_runs > 0) {
    out << ", new runs after a source restart " << p.new_runs << " (before the latest: solutions "
        << p.solutions_earlier_runs << ", increments " << p.increments_earlier_runs << ")";
  }
}

}  // namespace

std::string describePipeline(const PipelineView& v) {
  std::ostringstream out;
  describeCounts(v, out);
  describeOptional(v, out);
  return out.str();
}

}  // namespace navbus::nav_filter
