#include "navbus/gnss_data/rinex2.hpp"

#include <cmath>
#include <cstdlib>
#include <optional>
#include <sstream>

namespace navbus::gnss_data {

namespace {

/// Reads lines and names the place of an error.
class LineReader {
 public:
  LineReader(std::istream& in, std::string name) : in_(in), name_(std::move(name)) {}
  bool next(std::string& line) {
    if (!std::getline(in_, line)) return false;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    ++number_;
    return true;
  }
  std::string require(const char* what) {
    std::string line;
    if (!next(line)) fail(std::string("file ends inside ") + what);
    return line;
  }
  [[noreturn]] void fail(const std::string& message) const {
    throw RinexError(name_ + ":" + std::to_string(number_) + ": " + message);
  }
  std::string column(const std::string& line, std::size_t start, std::size_t width) const {
    return start < line.size() ? line.substr(start, width) : std::string();
  }
  static bool blank(const std::string& s) { return s.find_first_not_of(' ') == std::string::npos; }

  /// A number in columns [start, start + width); Fortran 'D' exponents accepted.
  double number(const std::string& line, std::size_t start, std::size_t width,
                const char* field) const {
    const std::string original = column(line, start, width);
    if (blank(original)) fail(std::string("field '") + field + "' is empty");
    std::string text = original;
    for (char& c : text) {
      if (c == 'D' || c == 'd') c = 'E';
    }
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || !blank(std::string(end)) || !std::isfinite(v)) {
      fail(std::string("field '") + field + "' is not a number: '" + original + "'");
    }
    return v;
  }
  int integer(const std::string& line, std::size_t start, std::size_t width,
              const char* field) const {
    const double v = number(line, start, width, field);
    if (v != std::floor(v)) fail(std::string("field '") + field + "' is not an integer");
    return static_cast<int>(v);
  }

 private:
  std::istream& in_;
  std::string name_;
  int number_{0};
};

std::string label(const std::string& line) {
  std::string l = line.size() > 60 ? line.substr(60) : std::string();
  while (!l.empty() && l.back() == ' ') l.pop_back();
  return l;
}

int fullYear(int two_digit) {
  return two_digit < 80 ? 2000 + two_digit : 1900 + two_digit;
}

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(' ');
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(' ') - b + 1);
}

/// The major version of a "RINEX VERSION / TYPE" line: 2 or 3, else an error.
int majorVersion(const LineReader& r, const std::string& version) {
  if (!version.empty() && (version[0] == '2' || version[0] == '3')) return version[0] - '0';
  r.fail("RINEX version '" + version + "' is not 2.xx or 3.xx");
}

/// RINEX 3 "SYS / # / OBS TYPES": the system's count, then 13 types a line (continuation lines
/// have a blank system).
void readSystemTypes(LineReader& r, const std::string& line, RinexObservationFile& f, char& system,
                     std::size_t& count) {
  if (r.column(line, 0, 1) != " ") {
    system = r.column(line, 0, 1)[0];
    count = static_cast<std::size_t>(r.integer(line, 3, 3, "SYS / # / OBS TYPES"));
  }
  std::vector<std::string>& types = f.system_types[system];
  for (std::size_t i = 0; i < 13 && types.size() < count; ++i)
    types.push_back(trimmed(r.column(line, 7 + 4 * i, 3)));
}

void readObservationHeader(LineReader& r, RinexObservationFile& f) {
  std::string line;
  bool version_seen = false;
  std::size_t type_count = 0;
  char system = ' ';
  std::size_t system_count = 0;
  while (r.next(line)) {
    const std::string l = label(line);
    if (l == "RINEX VERSION / TYPE") {
      f.version = trimmed(r.column(line, 0, 9));
      f.major_version = majorVersion(r, f.version);
      const std::string type = r.column(line, 20, 1);
      if (type != "O") r.fail("file type '" + type + "' is not O (observation)");
      version_seen = true;
    } else if (l == "SYS / # / OBS TYPES") {
      readSystemTypes(r, line, f, system, system_count);
    } else if (l == "MARKER NAME") {
      f.marker = trimmed(r.column(line, 0, 60));
    } else if (l == "APPROX POSITION XYZ") {
      for (int i = 0; i < 3; ++i) {
        f.approx_position_ecef_m[i] =
            r.number(line, 14 * static_cast<std::size_t>(i), 14, "APPROX POSITION XYZ");
      }
    } else if (l == "# / TYPES OF OBSERV") {
      if (f.types.empty()) {
        type_count = static_cast<std::size_t>(r.integer(line, 0, 6, "# / TYPES OF OBSERV"));
      }
      for (std::size_t i = 0; i < 9 && f.types.size() < type_count; ++i) {
        f.types.push_back(trimmed(r.column(line, 6 + 6 * i, 6)));
      }
    } else if (l == "INTERVAL") {
      f.interval_s = r.number(line, 0, 10, "INTERVAL");
    } else if (l == "END OF HEADER") {
      if (!version_seen) r.fail("no 'RINEX VERSION / TYPE' line before END OF HEADER");
      if (f.major_version == 3) {
        // The GPS observables are the file's types; other systems' satellites are counted.
        const auto gps = f.system_types.find('G');
        if (gps == f.system_types.end() || gps->second.empty())
          r.fail("'SYS / # / OBS TYPES' lists no GPS (G) observation type");
        f.types = gps->second;
        return;
      }
      if (f.types.empty() || f.types.size() != type_count) {
        r.fail("'# / TYPES OF OBSERV' lists " + std::to_string(f.types.size()) + " of " +
               std::to_string(type_count) + " types");
      }
      return;
    }
  }
  r.fail("no END OF HEADER");
}

/// Satellite list of an epoch line (and its continuation lines).
std::vector<std::pair<char, int>> readSatelliteList(LineReader& r, std::string line, int count) {
  std::vector<std::pair<char, int>> sats;
  for (int i = 0; i < count; ++i) {
    if (i > 0 && i % 12 == 0) line = r.require("an epoch's satellite list");
    const std::size_t col = 32 + 3 * static_cast<std::size_t>(i % 12);
    const std::string sys = r.column(line, col, 1);
    const char system = (sys.empty() || sys == " ") ? 'G' : sys[0];
    sats.emplace_back(system, r.integer(line, col + 1, 2, "satellite number"));
  }
  return sats;
}

}  // namespace

double gpsSecondsFromCalendar(int year, int month, int day, int hour, int minute, double second) {
  // Days from 1970-01-01 in the proleptic Gregorian calendar (civil-from-days inverted:
  // March-based years put the leap day last).
  const int y = year - (month <= 2 ? 1 : 0);
  const int era = (y >= 0 ? y : y - 399) / 400;
  const int yoe = y - era * 400;
  const int doy = (153 * (month + (month > 2 ? -3 : 9)) + 2) / 5 + day - 1;
  const int doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  const long days_1970 = static_cast<long>(era) * 146097 + doe - 719468;
  constexpr long kGpsEpochDays1970 = 3657;  // 1980-01-06
  return static_cast<double>(days_1970 - kGpsEpochDays1970) * 86400.0 + hour * 3600.0 +
         minute * 60.0 + second;
}

int RinexObservationFile::typeIndex(const std::string& type) const {
  for (std::size_t i = 0; i < types.size(); ++i) {
    if (types[i] == type) return static_cast<int>(i);
  }
  return -1;
}

namespace {

/// An epoch with flag 2..6 carries `count` special records (header lines, cycle slips): they
/// are skipped and counted. True when the epoch was one.
bool skippedEvent(LineReader& r, int flag, int count, RinexObservationFile& f) {
  if (flag < 2) return false;
  for (int i = 0; i < count; ++i) r.require("an event record");
  ++f.event_records;
  return true;
}

/// One observation field (F14.3 in 16 columns), or nothing when blank.
std::optional<double> observation(const LineReader& r, const std::string& line, std::size_t col) {
  if (LineReader::blank(r.column(line, col, 14))) return std::nullopt;
  return r.number(line, col, 14, "observation");
}

/// RINEX 3 epochs: "> yyyy mm dd hh mm ss.sssssss  f nnn", then one line per satellite
/// ("G10" and 16 columns per observable of its system).
void readObservationsV3(LineReader& r, RinexObservationFile& f) {
  std::string line;
  while (r.next(line)) {
    if (LineReader::blank(line)) continue;
    if (line[0] != '>') r.fail("'" + line.substr(0, 20) + "' is not an epoch record ('>')");
    const int flag = r.integer(line, 31, 1, "epoch flag");
    const int count = r.integer(line, 32, 3, "number of satellites");
    if (skippedEvent(r, flag, count, f)) continue;
    RinexObservationEpoch e;
    e.flag = flag;
    e.time_s =
        gpsSecondsFromCalendar(r.integer(line, 2, 4, "year"), r.integer(line, 7, 2, "month"),
                               r.integer(line, 10, 2, "day"), r.integer(line, 13, 2, "hour"),
                               r.integer(line, 16, 2, "minute"), r.number(line, 18, 11, "second"));
    for (int i = 0; i < count; ++i) {
      const std::string sat = r.require("an epoch's observations");
      RinexSatelliteObservations s;
      s.system = sat[0] == ' ' ? 'G' : sat[0];
      s.prn = r.integer(sat, 1, 2, "satellite number");
      if (s.system == 'G') {
        for (std::size_t k = 0; k < f.types.size(); ++k)
          s.values.push_back(observation(r, sat, 3 + 16 * k));
      }
      e.satellites.push_back(std::move(s));
    }
    f.epochs.push_back(std::move(e));
  }
}

}  // namespace

RinexObservationFile readObservationFile(std::istream& in, const std::string& name) {
  LineReader r(in, name);
  RinexObservationFile f;
  readObservationHeader(r, f);
  if (f.major_version == 3) {
    readObservationsV3(r, f);
    return f;
  }
  const std::size_t lines_per_sat = (f.types.size() + 4) / 5;
  std::string line;
  while (r.next(line)) {
    if (LineReader::blank(line)) continue;
    const int flag = r.integer(line, 28, 1, "epoch flag");
    const int count = r.integer(line, 29, 3, "number of satellites");
    if (skippedEvent(r, flag, count, f)) continue;
    RinexObservationEpoch e;
    e.flag = flag;
    e.time_s = gpsSecondsFromCalendar(
        fullYear(r.integer(line, 1, 2, "year")), r.integer(line, 4, 2, "month"),
        r.integer(line, 7, 2, "day"), r.integer(line, 10, 2, "hour"),
        r.integer(line, 13, 2, "minute"), r.number(line, 15, 11, "second"));
    for (const auto& [system, prn] : readSatelliteList(r, line, count)) {
      RinexSatelliteObservations s;
      s.system = system;
      s.prn = prn;
      for (std::size_t l = 0; l < lines_per_sat; ++l) {
        const std::string obs_line = r.require("an epoch's observations");
        for (std::size_t k = 0; k < 5 && s.values.size() < f.types.size(); ++k)
          s.values.push_back(observation(r, obs_line, 16 * k));
      }
      e.satellites.push_back(std::move(s));
    }
    f.epochs.push_back(std::move(e));
  }
  return f;
}

RinexNavigationFile readNavigationFile(std::istream& in, const std::string& name) {
  LineReader r(in, name);
  RinexNavigationFile f;
  std::string line;
  bool header_done = false;
  int major = 2;
  while (!header_done && r.next(line)) {
    const std::string l = label(line);
    if (l == "RINEX VERSION / TYPE") {
      f.version = trimmed(r.column(line, 0, 9));
      major = majorVersion(r, f.version);
      const std::string type = r.column(line, 20, 1);
      if (type != "N") r.fail("file type '" + type + "' is not N (navigation)");
    } else if (l == "ION ALPHA" || l == "ION BETA") {
      auto& target = l == "ION ALPHA" ? f.iono.alpha : f.iono.beta;
      for (std::size_t i = 0; i < 4; ++i) target[i] = r.number(line, 2 + 12 * i, 12, l.c_str());
      f.has_iono = true;
    } else if (l == "IONOSPHERIC CORR" &&
               (r.column(line, 0, 4) == "GPSA" || r.column(line, 0, 4) == "GPSB")) {
      // RINEX 3: GPSA alpha0..3, GPSB beta0..3.
      auto& target = r.column(line, 0, 4) == "GPSA" ? f.iono.alpha : f.iono.beta;
      for (std::size_t i = 0; i < 4; ++i)
        target[i] = r.number(line, 5 + 12 * i, 12, "IONOSPHERIC CORR");
      f.has_iono = true;
    } else if (l == "LEAP SECONDS") {
      f.leap_seconds = r.integer(line, 0, 6, "LEAP SECONDS");
    } else if (l == "END OF HEADER") {
      header_done = true;
    }
  }
  if (!header_done) r.fail("no END OF HEADER");
  if (f.version.empty()) r.fail("no 'RINEX VERSION / TYPE' line");
  // RINEX 3 records are one column further right and name their system; GLONASS and SBAS
  // records have 3 orbit lines, the others 7.
  const std::size_t shift = major == 3 ? 1 : 0;
  while (r.next(line)) {
    if (LineReader::blank(line)) continue;
    core::gps::BroadcastEphemeris e;
    if (major == 3 && line[0] != 'G') {
      const int orbit_lines = (line[0] == 'R' || line[0] == 'S') ? 3 : 7;
      for (int k = 0; k < orbit_lines; ++k) r.require("a broadcast orbit record");
      ++f.other_systems;
      continue;
    }
    e.sv_id = r.integer(line, shift, 2, "PRN");
    if (e.sv_id < 1 || e.sv_id > 32) r.fail("PRN " + std::to_string(e.sv_id) + " is not 1..32");
    if (major == 3) {
      e.toc_s = gpsSecondsFromCalendar(
          r.integer(line, 4, 4, "toc year"), r.integer(line, 9, 2, "toc month"),
          r.integer(line, 12, 2, "toc day"), r.integer(line, 15, 2, "toc hour"),
          r.integer(line, 18, 2, "toc minute"), r.number(line, 21, 2, "toc second"));
    } else {
      e.toc_s = gpsSecondsFromCalendar(
          fullYear(r.integer(line, 3, 2, "toc year")), r.integer(line, 6, 2, "toc month"),
          r.integer(line, 9, 2, "toc day"), r.integer(line, 12, 2, "toc hour"),
          r.integer(line, 15, 2, "toc minute"), r.number(line, 17, 5, "toc second"));
    }
    e.af0_s = r.number(line, 22 + shift, 19, "af0");
    e.af1_sps = r.number(line, 41 + shift, 19, "af1");
    e.af2_sps2 = r.number(line, 60 + shift, 19, "af2");
    // Broadcast orbit lines 1-7: four 19-column fields from column 4.
    static constexpr const char* kNames[7][4] = {
        {"IODE", "Crs", "Delta n", "M0"},
        {"Cuc", "e", "Cus", "sqrt(A)"},
        {"Toe", "Cic", "OMEGA", "Cis"},
        {"i0", "Crc", "omega", "OMEGA DOT"},
        {"IDOT", "codes on L2", "GPS week", "L2 P data flag"},
        {"SV accuracy", "SV health", "TGD", "IODC"},
        {"transmission time", "fit interval", "spare", "spare"}};
    std::array<std::array<double, 4>, 7> o{};
    for (std::size_t k = 0; k < 7; ++k) {
      const std::string orbit = r.require("a broadcast orbit record");
      for (std::size_t j = 0; j < 4; ++j) {
        const std::size_t col = 3 + shift + 19 * j;
        const std::string field = r.column(orbit, col, 19);
        // Spare fields and the optional fit interval of the last line may be blank.
        o[k][j] = LineReader::blank(field) ? 0.0 : r.number(orbit, col, 19, kNames[k][j]);
      }
    }
    e.iode = o[0][0];
    e.crs_m = o[0][1];
    e.delta_n_radps = o[0][2];
    e.m0_rad = o[0][3];
    e.cuc_rad = o[1][0];
    e.eccentricity = o[1][1];
    e.cus_rad = o[1][2];
    e.sqrt_a_sqrtm = o[1][3];
    const double toe_sow = o[2][0];
    e.cic_rad = o[2][1];
    e.omega0_rad = o[2][2];
    e.cis_rad = o[2][3];
    e.i0_rad = o[3][0];
    e.crc_m = o[3][1];
    e.argument_of_perigee_rad = o[3][2];
    e.omega_dot_radps = o[3][3];
    e.idot_radps = o[4][0];
    const double week = o[4][2];  // continuous GPS week (RINEX does not roll it over at 1024)
    e.accuracy_m = o[5][0];
    e.health = static_cast<int>(o[5][1]);
    e.tgd_s = o[5][2];
    if (!(e.sqrt_a_sqrtm > 0.0) || week < 1.0 || toe_sow < 0.0 || toe_sow >= 604800.0) {
      r.fail("PRN " + std::to_string(e.sv_id) + ": orbit with sqrt(A) " +
             std::to_string(e.sqrt_a_sqrtm) + ", week " + std::to_string(week) + ", toe " +
             std::to_string(toe_sow) + " s is not a GPS orbit");
    }
    e.toe_s = week * core::gps::kSecondsPerWeek + toe_sow;
    f.ephemerides.push_back(e);
  }
  return f;
}

EpochPseudoranges pseudoranges(const RinexObservationEpoch& epoch, int type_index) {
  EpochPseudoranges out;
  for (const RinexSatelliteObservations& s : epoch.satellites) {
    if (s.system != 'G') {
      ++out.other_systems;
      continue;
    }
    const auto& v = s.values[static_cast<std::size_t>(type_index)];
    if (!v) {
      ++out.missing;
      continue;
    }
    out.observations.push_back({s.prn, *v});
  }
  return out;
}

}  // namespace navbus::gnss_data
