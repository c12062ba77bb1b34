#include "navbus/evaluation/fault_evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "navbus/records/formatters.hpp"

namespace navbus::evaluation {

namespace {

bool gnssFault(const sim::Fault& f) {
  return f.kind == sim::FaultKind::kPseudorangeRamp || f.kind == sim::FaultKind::kPseudorangeStep ||
         f.kind == sim::FaultKind::kReceiverClockJump || f.kind == sim::FaultKind::kGnssMultipath;
}

/// `sensor_id`: the unit a parity (or lanes) decision or candidate names, the receiver a
/// "receivers" one names; 0 for the GLR's, which are about the filter's own IMU (the scenario's,
/// unit 0).
bool matches(const sim::Fault& f, navbus::FaultSource source, int sv_id, int axis,
             std::uint32_t sensor_id) {
  if (f.kind == sim::FaultKind::kReceiverClockJump)
    return source == navbus::SOURCE_RECEIVER_CLOCK && sensor_id == f.receiver_id;
  if (f.kind == sim::FaultKind::kPseudorangeRamp || f.kind == sim::FaultKind::kPseudorangeStep ||
      f.kind == sim::FaultKind::kGnssMultipath) {
    return source == navbus::SOURCE_SATELLITE && sv_id == f.sv_id;
  }
  const navbus::FaultSource want = f.sensor == sim::SensorKind::kAccelerometer
                                       ? navbus::SOURCE_ACCELEROMETER
                                       : navbus::SOURCE_GYRO;
  const bool unit = sensor_id == 0 ? f.unit == 0 : sensor_id == f.sensor_id;
  return source == want && axis == f.axis && unit;
}

std::uint32_t parityUnit(const navbus::FaultDecision& d) {
  return d.detector() == "parity" || d.detector() == "lanes" || d.detector() == "receivers"
             ? d.sensor_id()
             : 0;
}

double trueMagnitude(const sim::Fault& f) {
  if (f.kind == sim::FaultKind::kPseudorangeRamp || f.kind == sim::FaultKind::kImuBiasRamp)
    return f.slope;
  // A pseudorange step as the cross-receiver test reports it: the reference receiver's range
  // minus the other's.
  if (f.kind == sim::FaultKind::kPseudorangeStep && f.receiver != 0) return -f.magnitude;
  return f.magnitude;
}

std::string describe(const navbus::FaultDecision& d) {
  std::ostringstream s;
  switch (d.source()) {
    case navbus::SOURCE_ACCELEROMETER:
      s << "accel "
        << "xyz"[d.axis() % 3];
      if (parityUnit(d) != 0) s << " imu " << d.sensor_id();
      break;
    case navbus::SOURCE_GYRO:
      s << "gyro "
        << "xyz"[d.axis() % 3];
      if (parityUnit(d) != 0) s << " imu " << d.sensor_id();
      break;
    case navbus::SOURCE_SATELLITE:
      s << "sv " << d.sv_id() << (d.shape() == navbus::SHAPE_RAMP ? " ramp" : " step");
      break;
    case navbus::SOURCE_RECEIVER_CLOCK:
      s << "clock rx " << d.sensor_id();
      break;
    default:
      s << "source " << static_cast<int>(d.source());
  }
  s << " " << d.magnitude();
  if (d.ambiguous() && d.candidates().size() > 1) {
    const auto& c = d.candidates()[1];
    s << " | "
      << (c.source() == navbus::SOURCE_SATELLITE ? "sv "
          : c.source() == navbus::SOURCE_GYRO    ? "gyro "
                                                 : "accel ")
      << (c.source() == navbus::SOURCE_SATELLITE ? std::to_string(c.sv_id())
                                                 : std::string(1, "xyz"[c.axis() % 3]));
  }
  return s.str();
}

bool insideEnvelope(const EpochError& e) {
  for (int i = 0; i < 3; ++i) {
    if (std::abs(e.pos_ned_m[i]) > 3.0 * e.pos_sigma_ned_m[i]) return false;
  }
  return true;
}

double recoveryTime(const std::vector<EpochError>& errors, std::int64_t decision_ns) {
  constexpr std::int64_t kStay = 30'000'000'000;
  for (std::size_t i = 0; i < errors.size(); ++i) {
    if (errors[i].time_ns < decision_ns) continue;
    bool stays = true;
    std::size_t j = i;
    for (; j < errors.size() && errors[j].time_ns <= errors[i].time_ns + kStay; ++j) {
      if (!insideEnvelope(errors[j])) {
        stays = false;
        break;
      }
    }
    if (stays) return 1e-9 * static_cast<double>(errors[i].time_ns - decision_ns);
    i = j;  // the next candidate starts after the epoch that left the envelope
  }
  return std::nan("");
}

}  // namespace

bool writeGlrCsv(const std::string& path,
                 const std::vector<fault_manager::GlrEpochStatistic>& trace) {
  std::ofstream f(path);
  f << "time_gps_ns,statistic,threshold,onset_epochs_ago,detected\n";
  for (const fault_manager::GlrEpochStatistic& e : trace) {
    f << e.time_ns << "," << records::formatNumber(e.statistic) << ","
      << records::formatNumber(e.threshold) << "," << e.onset_epochs_ago << ","
      << (e.detected ? 1 : 0) << "\n";
  }
  return static_cast<bool>(f);
}

bool writeParityCsv(const std::string& path, const std::vector<OfflineResult::ParityEpoch>& trace) {
  std::ofstream f(path);
  f << "time_gps_ns,gyro_statistic,accelerometer_statistic,gyro_threshold,"
       "accelerometer_threshold\n";
  for (const OfflineResult::ParityEpoch& e : trace) {
    f << e.time_ns << "," << records::formatNumber(e.gyro) << ","
      << records::formatNumber(e.accelerometer) << "," << records::formatNumber(e.gyro_threshold)
      << "," << records::formatNumber(e.accelerometer_threshold) << "\n";
  }
  return static_cast<bool>(f);
}

std::optional<sim::Fault> detectableFault(const sim::FaultSchedule& schedule) {
  for (const sim::Fault& f : schedule.faults()) {
    if (f.kind == sim::FaultKind::kImuBiasStep || f.kind == sim::FaultKind::kImuBiasRamp ||
        f.kind == sim::FaultKind::kImuScaleFactorStep ||
        f.kind == sim::FaultKind::kImuNoiseIncrease || gnssFault(f))
      return f;
  }
  return std::nullopt;
}

namespace {
/// The first naming of one source after the fault: a decision that is not ambiguous (the
/// parity test's, or the fault manager's "lanes" decision when the lanes chose between two
/// suspects).
void noteNamed(const OfflineResult& r, const sim::Fault& fault, std::int64_t start_ns,
               FaultRunOutcome& out) {
  for (const navbus::FaultDecision& d : r.decisions) {
    const double t =
        1e-9 * static_cast<double>(static_cast<std::int64_t>(d.time_gps_ns()) - start_ns);
    if (d.event() != navbus::EVENT_FAULT_DETECTED || d.ambiguous() || t < fault.start_s) continue;
    out.named_s = t;
    out.named_correct = matches(fault, d.source(), d.sv_id(), d.axis(), parityUnit(d));
    return;
  }
}
}  // namespace

FaultRunOutcome evaluateRun(const OfflineResult& r, const std::optional<sim::Fault>& fault,
                            std::int64_t start_ns, std::uint64_t seed) {
  FaultRunOutcome out;
  out.seed = seed;
  const double fault_s = fault ? fault->start_s : 1e300;
  out.decisions = static_cast<int>(r.decisions.size());
  for (const navbus::FaultDecision& d : r.decisions) {
    if (d.event() != navbus::EVENT_FAULT_DETECTED) continue;
    const double t =
        1e-9 * static_cast<double>(static_cast<std::int64_t>(d.time_gps_ns()) - start_ns);
    if (t < fault_s) {
      ++out.false_alarms;
      continue;
    }
    if (out.detected) continue;
    out.detected = true;
    out.detection_s = t;
    out.onset_s =
        1e-9 * static_cast<double>(static_cast<std::int64_t>(d.onset_time_gps_ns()) - start_ns);
    out.decided = describe(d);
    out.ambiguous = d.ambiguous();
    const bool imu_truth = !gnssFault(*fault);
    const bool imu_decided =
        d.source() == navbus::SOURCE_ACCELEROMETER || d.source() == navbus::SOURCE_GYRO;
    // (a receiver's clock is a GNSS class: not an IMU)
    out.class_correct = imu_truth == imu_decided;
    out.source_correct = matches(*fault, d.source(), d.sv_id(), d.axis(), parityUnit(d));
    double magnitude = out.source_correct ? d.magnitude() : std::nan("");
    for (const auto& c : d.candidates()) {
      if (matches(*fault, c.source(), c.sv_id(), c.axis(), c.sensor_id())) {
        out.truth_among_candidates = true;
        if (std::isnan(magnitude)) magnitude = c.magnitude();
      }
    }
    out.magnitude_error = (magnitude - trueMagnitude(*fault)) / trueMagnitude(*fault);
    // A ramp named as a step (or the reverse) has a magnitude in another unit.
    // An IMU ramp is detected as the step it has grown to (the parity GLR tests steps): its
    // shape is not scored, nor is its magnitude.
    const bool ramp = fault->kind == sim::FaultKind::kPseudorangeRamp;
    out.shape_correct = !ramp || d.shape() == navbus::SHAPE_RAMP;
    // A scale-factor step or a noise increase is decided as the bias it looks like: no
    // magnitude of the same kind to compare.
    if (!out.shape_correct || fault->kind == sim::FaultKind::kImuBiasRamp ||
        fault->kind == sim::FaultKind::kImuScaleFactorStep ||
        fault->kind == sim::FaultKind::kImuNoiseIncrease ||
        fault->kind == sim::FaultKind::kGnssMultipath)
      out.magnitude_error = std::nan("");
    for (const navbus::FilterCommand& c : r.commands) {
      if (c.decision_id() == d.decision_id() && c.kind() == navbus::CMD_COMPENSATE_BIAS &&
          matches(*fault, c.sensor(), 0, c.axis(), 0))
        out.commanded_error = (c.bias() - trueMagnitude(*fault)) / trueMagnitude(*fault);
    }
    out.recovery_s = recoveryTime(r.errors, static_cast<std::int64_t>(d.time_gps_ns()));
  }
  if (fault) noteNamed(r, *fault, start_ns, out);
  return out;
}

namespace {
void printNamed(const sim::Fault& fault, const std::vector<FaultRunOutcome>& runs) {
  int right = 0, wrong = 0, never = 0, within_60 = 0;
  double sum = 0.0, most = 0.0;
  for (const FaultRunOutcome& o : runs) {
    if (!o.detected) continue;
    if (std::isnan(o.named_s)) {
      ++never;
      continue;
    }
    if (!o.named_correct) {
      ++wrong;
      continue;
    }
    ++right;
    const double after = o.named_s - fault.start_s;
    sum += after;
    most = std::max(most, after);
    within_60 += after <= 60.0 ? 1 : 0;
  }
  std::printf(
      "  named (the first decision not ambiguous, the lanes' between two suspects included): the "
      "faulty source in %d runs (within 60 s of the onset in %d; after it %.1f s on average, "
      "%.1f s at most), another in %d, never in %d\n",
      right, within_60, right ? sum / right : std::nan(""), right ? most : std::nan(""), wrong,
      never);
}
}  // namespace

void printFaultTable(const std::string& label, const std::optional<sim::Fault>& fault,
                     const std::vector<FaultRunOutcome>& runs, double hours_per_run) {
  int detected = 0, class_ok = 0, source_ok = 0, honest = 0, false_alarms = 0, shape_ok = 0;
  double sum_t = 0, min_t = 1e300, max_t = -1e300, sum_mag = 0;
  int mag_n = 0, cmd_n = 0, recovered_10s = 0, recovered = 0;
  double sum_cmd = 0;
  std::vector<double> recovery;
  int most_decisions = 0;
  for (const FaultRunOutcome& o : runs) {
    false_alarms += o.false_alarms;
    most_decisions = std::max(most_decisions, o.decisions);
    if (!o.detected) continue;
    ++detected;
    sum_t += o.detection_s;
    min_t = std::min(min_t, o.detection_s);
    max_t = std::max(max_t, o.detection_s);
    class_ok += o.class_correct ? 1 : 0;
    shape_ok += o.shape_correct ? 1 : 0;
    source_ok += o.source_correct ? 1 : 0;
    honest += (o.source_correct || (o.ambiguous && o.truth_among_candidates)) ? 1 : 0;
    if (std::isfinite(o.commanded_error)) {
      sum_cmd += std::abs(o.commanded_error);
      ++cmd_n;
    }
    if (std::isfinite(o.recovery_s)) {
      ++recovered;
      recovered_10s += o.recovery_s <= 10.0 ? 1 : 0;
      recovery.push_back(o.recovery_s);
    }
    if (std::isfinite(o.magnitude_error)) {
      sum_mag += std::abs(o.magnitude_error);
      ++mag_n;
    }
  }
  const double n = static_cast<double>(runs.size());
  std::printf("\n%s: %zu runs\n", label.c_str(), runs.size());
  if (fault) {
    std::printf(
        "  fault %s at %.1f s: detected %d/%zu; detection time mean %.1f s, min %.1f, max %.1f "
        "(%.1f s after onset on average)\n",
        sim::faultKindName(fault->kind), fault->start_s, detected, runs.size(),
        detected ? sum_t / detected : std::nan(""), detected ? min_t : std::nan(""),
        detected ? max_t : std::nan(""),
        detected ? sum_t / detected - fault->start_s : std::nan(""));
    std::printf(
        "  isolation: INS vs GNSS correct %.1f %%; source named first %.1f %%; source named or "
        "honestly ambiguous %.1f %% (of detected runs); shape (step/ramp) right %.1f %%; mean "
        "|magnitude error| %.1f %% (where the shape is right)\n",
        detected ? 100.0 * class_ok / detected : 0.0, detected ? 100.0 * source_ok / detected : 0.0,
        detected ? 100.0 * honest / detected : 0.0, detected ? 100.0 * shape_ok / detected : 0.0,
        mag_n ? 100.0 * sum_mag / mag_n : std::nan(""));
  }
  if (fault && detected) {
    std::sort(recovery.begin(), recovery.end());
    std::printf(
        "  compensation commanded in %d runs, mean |magnitude error| %.1f %%; position error back "
        "in the 3-sigma envelope (and staying 30 s) after the decision: median %.1f s, within "
        "10 s in %d/%d runs, never in %d\n",
        cmd_n, cmd_n ? 100.0 * sum_cmd / cmd_n : std::nan(""),
        recovery.empty() ? std::nan("") : recovery[recovery.size() / 2], recovered_10s, detected,
        detected - recovered);
  }
  if (fault && detected) printNamed(*fault, runs);
  std::printf("  false alarms: %d in %.2f h of data (%.3f per hour)%s\n", false_alarms,
              n * hours_per_run, false_alarms / std::max(n * hours_per_run, 1e-9),
              fault ? " (before the fault)" : "");
  std::printf("  most decisions in one run: %d\n", most_decisions);
  std::printf("  per run (seed: detection s, onset s, decision):");
  for (const FaultRunOutcome& o : runs) {
    if (o.detected) {
      std::printf(" [%llu: %.0f, %.0f, %s]", static_cast<unsigned long long>(o.seed), o.detection_s,
                  o.onset_s, o.decided.c_str());
    } else {
      std::printf(" [%llu: -]", static_cast<unsigned long long>(o.seed));
    }
  }
  std::printf("\n");
}

}  // namespace navbus::evaluation
