#include "navbus/bus/key_reader.hpp"

#include <algorithm>
#include <cmath>

namespace navbus::bus {

KeyReader::KeyReader(const YAML::Node& node, std::string where)
    : node_(node), where_(std::move(where)) {
  requireMapOrAbsent(node_, where_);
}

std::string KeyReader::path(const char* key) const {
  return where_.empty() ? std::string(key) : where_ + "." + key;
}

bool KeyReader::present(const char* key) const {
  return node_ && node_.IsMap() && node_[key];
}

bool KeyReader::read(const char* key, double& file_value, Range range) {
  keys_.emplace_back(key);
  if (!present(key)) return false;
  file_value = checkRange(get<double>(node_, where_, key, 0.0), range.lo, range.hi, path(key));
  return true;
}

void KeyReader::requireWhole(const char* key, double value) const {
  if (value != std::floor(value))
    throw ConfigError("configuration " + path(key) + " = " + std::to_string(value) +
                      " must be a whole number");
}

KeyReader& KeyReader::number(const char* key, double& value, Range range, FileUnit unit) {
  double v = 0.0;
  if (read(key, v, range)) value = unit.toSi(v);
  return *this;
}

KeyReader& KeyReader::seconds(const char* key, std::int64_t& value_ns, Range range_s) {
  double s = 0.0;
  if (read(key, s, range_s)) value_ns = std::llround(s * 1e9);
  return *this;
}

KeyReader& KeyReader::rateHz(const char* key, double& period_s, Range range_hz) {
  double hz = 0.0;
  if (read(key, hz, range_hz)) period_s = 1.0 / hz;
  return *this;
}

KeyReader& KeyReader::rateHz(const char* key, std::int64_t& period_ns, Range range_hz) {
  double hz = 0.0;
  if (read(key, hz, range_hz)) period_ns = std::llround(1.0 / hz * 1e9);
  return *this;
}

KeyReader& KeyReader::nested(std::initializer_list<const char*> keys) {
  for (const char* k : keys) keys_.emplace_back(k);
  return *this;
}

void KeyReader::finish(std::initializer_list<const char*> also) const {
  if (!node_ || node_.IsNull()) return;  // absent or empty: every default
  for (const auto& kv : node_) {
    const auto key = as<std::string>(kv.first, path("<key>"));
    const bool known =
        std::find(keys_.begin(), keys_.end(), key) != keys_.end() ||
        std::any_of(also.begin(), also.end(), [&key](const char* k) { return key == k; });
    if (!known) throw UnknownKeyError(path(key.c_str()));
  }
}

}  // namespace navbus::bus
