// Reading one block of a YAML configuration into a struct whose member initializers are the
// defaults. An absent key leaves its member as it is (the default lives once, beside the
// member); a present key is read, range-checked in the file's unit and converted to SI once.
// The reader collects the names it reads, so finish() refuses any other key without a second
// list of key paths.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "navbus/bus/config.hpp"

namespace navbus::bus {

/// How a number in the file becomes SI: one named conversion per unit, written out in the
/// order of its arithmetic (e.g. mg: `v * 1e-3 * kStandardGravity`). None: the file is in SI.
struct FileUnit {
  double (*to_si)(double) = nullptr;
  double toSi(double value) const { return to_si != nullptr ? to_si(value) : value; }
};

/// An inclusive range in the file's unit.
struct Range {
  double lo;
  double hi;
};

class KeyReader {
 public:
  /// `where`: the block's key path ("" for the top level); `node` may be absent (all defaults).
  KeyReader(const YAML::Node& node, std::string where);

  /// A number: its SI value is `value`; in the file it is in `unit`, within `range`.
  KeyReader& number(const char* key, double& value, Range range, FileUnit unit = {});
  /// A duration in seconds in the file, nanoseconds in the struct.
  KeyReader& seconds(const char* key, std::int64_t& value_ns, Range range_s);
  /// A rate in hertz in the file; the struct holds its period [s].
  KeyReader& rateHz(const char* key, double& period_s, Range range_hz);
  /// A rate in hertz in the file; the struct holds its period [ns].
  KeyReader& rateHz(const char* key, std::int64_t& period_ns, Range range_hz);
  /// A whole number within `range`.
  template <class Int>
  KeyReader& integer(const char* key, Int& value, Range range) {
    double v = static_cast<double>(value);
    if (read(key, v, range)) {
      requireWhole(key, v);
      value = static_cast<Int>(v);
    }
    return *this;
  }
  /// Any value yaml-cpp converts to T (bool, string, lists, maps), unchecked.
  template <class T>
  KeyReader& value(const char* key, T& out) {
    keys_.emplace_back(key);
    out = get<T>(node_, where_, key, out);
    return *this;
  }
  /// One of the named values.
  template <class Enum>
  KeyReader& choice(const char* key, Enum& out,
                    std::initializer_list<std::pair<const char*, Enum>> names) {
    keys_.emplace_back(key);
    if (!present(key)) return *this;
    const std::string text = get<std::string>(node_, where_, key, "");
    std::string list;
    for (const auto& [name, v] : names) {
      if (text == name) {
        out = v;
        return *this;
      }
      list += list.empty() ? name : std::string(" | ") + name;
    }
    throw ConfigError("configuration " + path(key) + " = '" + text + "' is not one of " + list);
  }
  /// Keys that other code reads (nested blocks): accepted by finish().
  KeyReader& nested(std::initializer_list<const char*> keys);
  /// Throws UnknownKeyError for a key of the block that nothing read (nor `also`).
  void finish(std::initializer_list<const char*> also = {}) const;

  bool present(const char* key) const;
  const YAML::Node& node() const { return node_; }
  /// "where.key" (or "key" at the top level).
  std::string path(const char* key) const;

 private:
  void requireWhole(const char* key, double value) const;
  /// Reads `key` into `file_value` (file unit) if present; true if it was.
  bool read(const char* key, double& file_value, Range range);

  YAML::Node node_;
  std::string where_;
  std::vector<std::string> keys_;
};

}  // namespace navbus::bus
