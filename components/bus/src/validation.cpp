#include "navbus/bus/validation.hpp"

#include <algorithm>

#include <cmath>
#include <sstream>
#include <string_view>

#include "navbus/bus/health.hpp"
#include "navbus/bus/streams.hpp"

namespace navbus::bus {

namespace {

// Field names are string views: a valid sample builds no string (the names are only spelled
// out in a rejection).
std::string indexed(std::string_view name, std::size_t i) {
  return std::string(name) + "[" + std::to_string(i) + "]";
}

template <std::size_t N>
std::optional<Rejection> finiteArray(const std::array<double, N>& a, std::string_view name) {
  for (std::size_t i = 0; i < N; ++i) {
    if (!std::isfinite(a[i])) {
      return Rejection{navbus::REJECT_NOT_FINITE, indexed(name, i), a[i]};
    }
  }
  return std::nullopt;
}

std::optional<Rejection> finite(double v, std::string_view name) {
  if (!std::isfinite(v)) {
    return Rejection{navbus::REJECT_NOT_FINITE, std::string(name), v};
  }
  return std::nullopt;
}

template <std::size_t N>
double norm(const std::array<double, N>& a) {
  double s = 0.0;
  for (double v : a) {
    s += v * v;
  }
  return std::sqrt(s);
}

std::optional<Rejection> range(double v, double lo, double hi, std::string_view name) {
  if (v < lo || v > hi) {
    return Rejection{navbus::REJECT_OUT_OF_RANGE, std::string(name), v};
  }
  return std::nullopt;
}

/// Every element > 0 (name[i] in the rejection).
template <std::size_t N>
std::optional<Rejection> positiveArray(const std::array<double, N>& a, std::string_view name) {
  for (std::size_t i = 0; i < N; ++i) {
    if (!(a[i] > 0.0)) return Rejection{navbus::REJECT_OUT_OF_RANGE, indexed(name, i), a[i]};
  }
  return std::nullopt;
}

/// One raw sample's own field names (the caller prefixes its place in the block).
std::optional<Rejection> validateRawSample(const navbus::ImuRawSample& x,
                                           const ValidationLimits& l) {
  if (auto r = finiteArray(x.angular_rate_b_radps(), "angular_rate_b_radps")) return r;
  if (auto r = finiteArray(x.specific_force_b_mps2(), "specific_force_b_mps2")) return r;
  if (auto r = range(norm(x.angular_rate_b_radps()), 0.0, l.max_angular_rate_radps,
                     "|angular_rate_b_radps|"))
    return r;
  return range(norm(x.specific_force_b_mps2()), 0.0, l.max_specific_force_mps2,
               "|specific_force_b_mps2|");
}

}  // namespace

std::string Rejection::describe() const {
  std::ostringstream out;
  out << rejectReasonName(reason) << ": " << field << " = " << value;
  return out.str();
}

std::optional<Rejection> validate(const navbus::ImuIncrement& s, const ValidationLimits& l) {
  if (auto r = finiteArray(s.delta_vel_b_mps(), "delta_vel_b_mps")) return r;
  if (auto r = finiteArray(s.delta_angle_b_rad(), "delta_angle_b_rad")) return r;
  if (s.interval_ns() == 0 || s.interval_ns() > l.max_interval_ns) {
    return Rejection{navbus::REJECT_BAD_INTERVAL, "interval_ns",
                     static_cast<double>(s.interval_ns())};
  }
  const double dt = 1e-9 * s.interval_ns();
  if (auto r = range(norm(s.delta_vel_b_mps()) / dt, 0.0, l.max_specific_force_mps2,
                     "|delta_vel_b_mps|/interval"))
    return r;
  if (auto r = range(norm(s.delta_angle_b_rad()) / dt, 0.0, l.max_angular_rate_radps,
                     "|delta_angle_b_rad|/interval"))
    return r;
  return std::nullopt;
}

std::optional<Rejection> validate(const navbus::ImuIncrementBlock& s, const ValidationLimits&) {
  if (s.increments().empty()) return Rejection{navbus::REJECT_OUT_OF_RANGE, "increments.size", 0.0};
  for (std::size_t i = 0; i < s.increments().size(); ++i) {
    if (s.increments()[i].sensor_id() != s.sensor_id()) {
      return Rejection{navbus::REJECT_INCONSISTENT, indexed("increments", i) + ".sensor_id",
                       static_cast<double>(s.increments()[i].sensor_id())};
    }
  }
  return std::nullopt;
}

namespace {
template <class Block>
std::optional<Rejection> validateBlock(const Block& s) {
  using Traits = SensorBlock<Block>;
  const auto& elements = Traits::elements(s);
  const std::string_view name = Traits::kElements;
  if (elements.empty()) {
    return Rejection{navbus::REJECT_OUT_OF_RANGE, std::string(name) + ".size", 0.0};
  }
  const std::uint32_t id = SensorMessage<Block>::sensorId(s);
  for (std::size_t i = 0; i < elements.size(); ++i) {
    const std::uint32_t element_id = SensorMessage<typename Traits::Element>::sensorId(elements[i]);
    if (element_id != id) {
      return Rejection{navbus::REJECT_INCONSISTENT, indexed(name, i) + "." + Traits::kIdField,
                       static_cast<double>(element_id)};
    }
  }
  return std::nullopt;
}
}  // namespace

std::optional<Rejection> validate(const navbus::GnssObservationEpochBlock& s,
                                  const ValidationLimits&) {
  return validateBlock(s);
}
std::optional<Rejection> validate(const navbus::GnssFixBlock& s, const ValidationLimits&) {
  return validateBlock(s);
}
std::optional<Rejection> validate(const navbus::StarTrackerAttitudeBlock& s,
                                  const ValidationLimits&) {
  return validateBlock(s);
}

std::optional<Rejection> validate(const navbus::ImuRawBlock& s, const ValidationLimits& l) {
  if (s.samples().empty()) {
    return Rejection{navbus::REJECT_OUT_OF_RANGE, "samples.size", 0.0};
  }
  if (s.sample_period_ns() == 0 || s.sample_period_ns() > l.max_interval_ns) {
    return Rejection{navbus::REJECT_BAD_INTERVAL, "sample_period_ns",
                     static_cast<double>(s.sample_period_ns())};
  }
  for (std::size_t i = 0; i < s.samples().size(); ++i) {
    if (auto r = validateRawSample(s.samples()[i], l)) {
      r->field = indexed("samples", i) + "." + r->field;  // its place, only when refused
      return r;
    }
  }
  return std::nullopt;
}

std::optional<Rejection> validate(const navbus::GnssObservationEpoch&, const ValidationLimits&) {
  return std::nullopt;
}

namespace {
/// The satellite's own field names (the caller prefixes its place in the epoch on a rejection:
/// a satellite that passes builds no string).
std::optional<Rejection> screenSatellite(const navbus::GnssSatelliteMeasurement& m,
                                         const ValidationLimits& l) {
  if (m.sv_id() < 1 || m.sv_id() > 32) {
    return Rejection{navbus::REJECT_UNKNOWN_SATELLITE, "sv_id", static_cast<double>(m.sv_id())};
  }
  if (auto r = finite(m.pseudorange_m(), "pseudorange_m")) return r;
  if (auto r = finite(m.pseudorange_rate_mps(), "pseudorange_rate_mps")) return r;
  if (auto r = finiteArray(m.sat_pos_ecef_m(), "sat_pos_ecef_m")) return r;
  if (auto r = finiteArray(m.sat_vel_ecef_mps(), "sat_vel_ecef_mps")) return r;
  if (auto r = finite(m.sat_clock_correction_m(), "sat_clock_correction_m")) return r;
  if (auto r = finite(m.sat_clock_drift_mps(), "sat_clock_drift_mps")) return r;
  if (auto r = finite(m.cn0_dbhz(), "cn0_dbhz")) return r;
  if (auto r = finite(m.pseudorange_sigma_m(), "pseudorange_sigma_m")) return r;
  if (auto r = finite(m.pseudorange_rate_sigma_mps(), "pseudorange_rate_sigma_mps")) return r;
  if (auto r = range(m.pseudorange_m(), l.min_pseudorange_m, l.max_pseudorange_m, "pseudorange_m"))
    return r;
  if (auto r = range(std::abs(m.pseudorange_rate_mps()), 0.0, l.max_pseudorange_rate_mps,
                     "pseudorange_rate_mps"))
    return r;
  if (auto r = range(norm(m.sat_pos_ecef_m()), l.min_sat_radius_m, l.max_sat_radius_m,
                     "|sat_pos_ecef_m|"))
    return r;
  if (auto r = range(m.cn0_dbhz(), 0.0, 70.0, "cn0_dbhz")) return r;
  if (auto r = range(m.pseudorange_sigma_m(), l.min_pseudorange_sigma_m, l.max_pseudorange_sigma_m,
                     "pseudorange_sigma_m"))
    return r;
  if (auto r = range(m.pseudorange_rate_sigma_mps(), l.min_pseudorange_rate_sigma_mps,
                     l.max_pseudorange_rate_sigma_mps, "pseudorange_rate_sigma_mps"))
    return r;
  return std::nullopt;
}
}  // namespace

std::vector<SatelliteRejection> screenSatellites(const navbus::GnssObservationEpoch& s,
                                                 const ValidationLimits& l) {
  std::vector<SatelliteRejection> out;
  const auto& sats = s.satellites();
  for (std::size_t i = 0; i < sats.size(); ++i) {
    if (auto r = screenSatellite(sats[i], l)) {
      r->field = indexed("satellites", i) + "." + r->field;
      out.push_back({i, *r});
      continue;
    }
    const auto same_id = [&](const navbus::GnssSatelliteMeasurement& o) {
      return o.sv_id() == sats[i].sv_id();
    };
    if (std::count_if(sats.begin(), sats.end(), same_id) > 1) {
      out.push_back(
          {i, Rejection{navbus::REJECT_DUPLICATE_SATELLITE, indexed("satellites", i) + ".sv_id",
                        static_cast<double>(sats[i].sv_id())}});
    }
  }
  return out;
}

std::optional<Rejection> validate(const navbus::GnssFix& s, const ValidationLimits& l) {
  if (auto r = finite(s.latitude_rad(), "latitude_rad")) return r;
  if (auto r = finite(s.longitude_rad(), "longitude_rad")) return r;
  if (auto r = finite(s.height_m(), "height_m")) return r;
  if (auto r = finiteArray(s.pos_ecef_m(), "pos_ecef_m")) return r;
  if (auto r = finiteArray(s.vel_ned_mps(), "vel_ned_mps")) return r;
  if (auto r = finiteArray(s.pos_sigma_ned_m(), "pos_sigma_ned_m")) return r;
  if (auto r = finiteArray(s.vel_sigma_ned_mps(), "vel_sigma_ned_mps")) return r;
  if (!s.valid()) return std::nullopt;  // a fix marked invalid is not used, so not judged further
  if (auto r = range(s.latitude_rad(), -M_PI / 2, M_PI / 2, "latitude_rad")) return r;
  if (auto r = range(s.longitude_rad(), -M_PI, M_PI, "longitude_rad")) return r;
  if (auto r = range(s.height_m(), l.min_height_m, l.max_height_m, "height_m")) return r;
  if (auto r = positiveArray(s.pos_sigma_ned_m(), "pos_sigma_ned_m")) return r;
  if (auto r = positiveArray(s.vel_sigma_ned_mps(), "vel_sigma_ned_mps")) return r;
  return std::nullopt;
}

std::optional<Rejection> validate(const navbus::StarTrackerAttitude& s, const ValidationLimits& l) {
  if (auto r = finiteArray(s.q_b_to_i(), "q_b_to_i")) return r;
  if (auto r = finiteArray(s.sigma_b_rad(), "sigma_b_rad")) return r;
  if (s.valid() && std::abs(norm(s.q_b_to_i()) - 1.0) > l.quaternion_norm_tolerance) {
    return Rejection{navbus::REJECT_BAD_QUATERNION, "|q_b_to_i|", norm(s.q_b_to_i())};
  }
  for (std::size_t i = 0; i < 3; ++i) {  // each > 0 and within the limit
    const double v = s.sigma_b_rad()[i];
    if (!(v > 0.0) || v > l.max_star_tracker_sigma_rad)
      return Rejection{navbus::REJECT_OUT_OF_RANGE, indexed("sigma_b_rad", i), v};
  }
  return std::nullopt;
}

std::optional<Rejection> validate(const navbus::FilterDiagnostics& s, const ValidationLimits&) {
  const std::size_t n = s.n(), m = s.m();
  auto inconsistent = [](const char* field, std::size_t got) {
    return Rejection{navbus::REJECT_INCONSISTENT, field, static_cast<double>(got)};
  };
  if (n == 0) return inconsistent("n", n);
  if (m == 0) return inconsistent("m", m);
  if (s.rows().size() != m) return inconsistent("rows.size()", s.rows().size());
  if (s.innovation().size() != m) return inconsistent("innovation.size()", s.innovation().size());
  if (s.innovation_cov().size() != m * m)
    return inconsistent("innovation_cov.size()", s.innovation_cov().size());
  if (s.h().size() != m * n) return inconsistent("h.size()", s.h().size());
  if (s.k().size() != n * m) return inconsistent("k.size()", s.k().size());
  if (s.phi().size() != n * n) return inconsistent("phi.size()", s.phi().size());
  auto finiteSeq = [](const auto& seq, const char* name) -> std::optional<Rejection> {
    for (std::size_t i = 0; i < seq.size(); ++i) {
      if (!std::isfinite(seq[i]))
        return Rejection{navbus::REJECT_NOT_FINITE, indexed(name, i), seq[i]};
    }
    return std::nullopt;
  };
  if (auto r = finiteSeq(s.innovation(), "innovation")) return r;
  if (auto r = finiteSeq(s.innovation_cov(), "innovation_cov")) return r;
  if (auto r = finiteSeq(s.h(), "h")) return r;
  if (auto r = finiteSeq(s.k(), "k")) return r;
  if (auto r = finiteSeq(s.phi(), "phi")) return r;
  if (!std::isfinite(s.process_noise_scale()))
    return Rejection{navbus::REJECT_NOT_FINITE, "process_noise_scale", s.process_noise_scale()};
  if (s.process_noise_scale() < 0.0)  // 0: a producer that does not report it
    return Rejection{navbus::REJECT_OUT_OF_RANGE, "process_noise_scale", s.process_noise_scale()};
  for (std::size_t i = 0; i < m; ++i) {
    const auto& row = s.rows()[i];
    const bool ranging =
        row.kind() == navbus::MEAS_PSEUDORANGE || row.kind() == navbus::MEAS_PSEUDORANGE_RATE;
    if (ranging && (row.sv_id() < 1 || row.sv_id() > 32)) {
      return Rejection{navbus::REJECT_UNKNOWN_SATELLITE, indexed("rows", i) + ".sv_id",
                       static_cast<double>(row.sv_id())};
    }
    if (!(s.innovation_cov()[i * m + i] > 0.0)) {
      return Rejection{navbus::REJECT_OUT_OF_RANGE, indexed("innovation_cov", i * m + i),
                       s.innovation_cov()[i * m + i]};
    }
  }
  return std::nullopt;
}

SequenceTracker::Outcome SequenceTracker::check(std::uint32_t sensor_id, std::uint64_t seq,
                                                std::uint64_t time_ns) {
  Outcome out;
  auto it = last_.find(sensor_id);
  if (it != last_.end()) {
    const Last& last = it->second;
    if (seq == last.seq && time_ns == last.time_ns) {
      out.rejection = Rejection{navbus::REJECT_DUPLICATE, "seq", static_cast<double>(seq)};
      return out;
    }
    if (time_ns <= last.time_ns) {
      if (seq < last.seq && confirmsRestart(sensor_id, seq, time_ns)) {
        out.source_restarted = true;
        last_[sensor_id] = Last{seq, time_ns};
        return out;
      }
      out.rejection =
          Rejection{navbus::REJECT_TIME_NOT_MONOTONIC, "time_gps_ns", static_cast<double>(time_ns)};
      return out;
    }
    restart_candidate_.erase(sensor_id);  // the stream goes on: a stale sample, no restart
  }
  const std::uint64_t stream_latest = it != last_.end() ? it->second.time_ns : 0;
  std::uint64_t first_seq = seq;  // of a confirmed chain: its first sample's
  if (auto r = checkJump(sensor_id, seq, time_ns, stream_latest, out, first_seq)) {
    out.rejection = r;
    return out;
  }
  if (started_.insert(sensor_id).second && first_seq > 1) {
    out.missing = out.missing_before_first = first_seq - 1;
  } else if (it != last_.end() && !out.jump_adopted) {
    if (seq > it->second.seq + 1) {
      out.missing = seq - it->second.seq - 1;
    } else if (seq <= it->second.seq) {
      out.restarted = true;
    }
  }
  last_[sensor_id] = Last{seq, time_ns};
  if (reference_ != nullptr && time_ns > reference_->latest_ns) reference_->latest_ns = time_ns;
  return out;
}

bool SequenceTracker::continues(const Candidate& c, std::uint64_t seq,
                                std::uint64_t time_ns) const {
  return seq > c.seq && time_ns > c.time_ns &&
         (rule_.tolerance_ns == 0 || time_ns <= c.time_ns + rule_.tolerance_ns);
}

bool SequenceTracker::confirmsRestart(std::uint32_t sensor_id, std::uint64_t seq,
                                      std::uint64_t time_ns) {
  auto cand = restart_candidate_.find(sensor_id);
  const bool more = cand != restart_candidate_.end() && continues(cand->second, seq, time_ns);
  const int count = more ? cand->second.count + 1 : 1;
  if (count >= rule_.confirmations) {
    restart_candidate_.erase(sensor_id);
    return true;
  }
  restart_candidate_[sensor_id] = Candidate{seq, time_ns, count, seq};
  return false;
}

std::optional<Rejection> SequenceTracker::checkJump(std::uint32_t sensor_id, std::uint64_t seq,
                                                    std::uint64_t time_ns,
                                                    std::uint64_t stream_latest_ns, Outcome& out,
                                                    std::uint64_t& first_seq) {
  if (rule_.tolerance_ns == 0) return std::nullopt;
  const std::uint64_t latest =
      std::max(stream_latest_ns, reference_ != nullptr ? reference_->latest_ns : 0);
  auto cand = candidate_.find(sensor_id);
  if (latest == 0 || time_ns <= latest + rule_.tolerance_ns) {
    if (cand != candidate_.end()) candidate_.erase(cand);  // the stream goes on: a one-off
    return std::nullopt;
  }
  // Ahead of everything seen by more than the tolerance: a forward jump. It is adopted only
  // when the samples after it continue from it.
  const bool more = cand != candidate_.end() && continues(cand->second, seq, time_ns);
  const int count = more ? cand->second.count + 1 : 1;
  const std::uint64_t chain_first_seq = more ? cand->second.first_seq : seq;
  if (count >= rule_.confirmations) {
    candidate_.erase(sensor_id);
    out.jump_adopted = true;
    out.jump_held = count - 1;
    first_seq = chain_first_seq;
    return std::nullopt;
  }
  candidate_[sensor_id] = Candidate{seq, time_ns, count, chain_first_seq};
  out.jump_candidate = count;
  return Rejection{navbus::REJECT_TIME_JUMP, "time_gps_ns", static_cast<double>(time_ns)};
}

}  // namespace navbus::bus

#include <spdlog/spdlog.h>

namespace navbus::bus {

void StreamGate::reject(const Rejection& r, std::uint32_t sensor_id) {
  const std::uint64_t n = ++counters_.rejected[r.reason];
  bool first_of_sensor = false;
  if (SensorCounters* s = counters_.sensor(sensor_id))
    first_of_sensor = ++s->rejected == 1;
  else
    ++counters_.unlisted_sensor_samples;
  // Each kind the first time and every 1000th, and each listed sensor's first refusal: every
  // refused source is named once (units refused in blocks interleave in any order).
  if (n == 1 || n % 1000 == 0 || first_of_sensor) {
    spdlog::warn("{}: rejected sample of sensor {} ({}; {} rejected for this reason so far)",
                 topic_, sensor_id, r.describe(), n);
  }
}

void StreamGate::rejectElement(const Rejection& r, std::uint32_t sensor_id) {
  const std::uint64_t n = ++counters_.elements_rejected[r.reason];
  if (n == 1 || n % 1000 == 0) {
    spdlog::warn("{}: dropped an element of sensor {}'s sample, the rest kept ({}; {} so far)",
                 topic_, sensor_id, r.describe(), n);
  }
}

void StreamGate::admitHeld(std::uint32_t sensor_id, std::size_t n) {
  if (n == 0) return;
  auto it = counters_.rejected.find(navbus::REJECT_TIME_JUMP);
  const std::uint64_t undone =
      it == counters_.rejected.end() ? 0 : std::min<std::uint64_t>(n, it->second);
  if (undone > 0 && (it->second -= undone) == 0) counters_.rejected.erase(it);
  counters_.accepted += n;
  if (SensorCounters* s = counters_.sensor(sensor_id)) {
    s->rejected -= std::min(s->rejected, undone);
    s->accepted += n;
  }
  spdlog::info(
      "{}: the {} samples of sensor {} refused before the confirmed jump continue to it: used",
      topic_, n, sensor_id);
}

void StreamGate::unaccept(std::uint32_t sensor_id) {
  if (counters_.accepted > 0) --counters_.accepted;
  const auto it = counters_.sensors.find(sensor_id);
  if (it != counters_.sensors.end() && it->second.accepted > 0) --it->second.accepted;
  // An unlisted id's sample is counted once there, accepted or rejected: the reject after this
  // counts it again.
  if (it == counters_.sensors.end() && counters_.unlisted_sensor_samples > 0)
    --counters_.unlisted_sensor_samples;
}

void StreamGate::noteSequence(const SequenceTracker::Outcome& o, std::uint32_t sensor_id) {
  counters_.countAccepted(sensor_id, o.missing);
  if (SensorCounters* s = counters_.sensor(sensor_id); s && o.source_restarted)
    ++s->source_restarts;
  if (o.missing_before_first > 0) {
    spdlog::warn(
        "{}: the first sample taken is number {}: the {} before it were not received (the "
        "reader joined late or missed the start), counted as sequence gaps",
        topic_, o.missing_before_first + 1, o.missing_before_first);
  }
  if (o.restarted) {
    spdlog::info("{}: sequence restarted (writer restart)", topic_);
  }
  if (o.source_restarted) {
    ++counters_.source_restarts;
    spdlog::warn(
        "{}: the source restarted (time and sequence went back, confirmed by the samples "
        "after it): a new run",
        topic_);
  }
  if (o.jump_adopted) {
    spdlog::warn("{}: a forward time jump confirmed by the samples after it: adopted", topic_);
  }
}

}  // namespace navbus::bus
