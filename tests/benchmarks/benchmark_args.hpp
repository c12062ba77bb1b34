// The benchmarks' two positional arguments, a scenario directory and a count: --help prints the
// usage, a count that is not a positive integer is an error naming it (exit 2, as the tools'
// usage errors), and benchmarkMain turns an unreadable scenario file into a message and exit 2
// instead of an uncaught exception.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <optional>
#include <string>

namespace navbus::bench {

struct DirAndCount {
  std::string dir;
  int count;
};

/// argv: [DIR [COUNT]]; nullopt when main should return `exit_code` (help or a bad count).
inline std::optional<DirAndCount> parseDirAndCount(int argc, char** argv, int default_count,
                                                   const char* count_name, int& exit_code) {
  const std::string first = argc > 1 ? argv[1] : "";
  if (first == "-h" || first == "--help") {
    std::printf("usage: %s [SCENARIO_DIR (default sim/scenarios) [%s (default %d)]]\n", argv[0],
                count_name, default_count);
    exit_code = 0;
    return std::nullopt;
  }
  DirAndCount a{argc > 1 ? first : "sim/scenarios", default_count};
  if (argc > 2) {
    char* end = nullptr;
    const long v = std::strtol(argv[2], &end, 10);
    if (end == argv[2] || *end != '\0' || v <= 0 || v > 100'000'000) {
      std::fprintf(stderr, "%s: %s must be a positive integer, got '%s'\n", argv[0], count_name,
                   argv[2]);
      exit_code = 2;
      return std::nullopt;
    }
    a.count = static_cast<int>(v);
  }
  return a;
}

/// A benchmark's main: its arguments (parseDirAndCount), then body(dir, count); a failure
/// (e.g. a scenario file that cannot be read) is printed, exit 2.
inline int benchmarkMain(int argc, char** argv, int default_count, const char* count_name,
                         int (*body)(const std::string& dir, int count)) {
  int exit_code = 0;
  const auto args = parseDirAndCount(argc, argv, default_count, count_name, exit_code);
  if (!args) return exit_code;
  try {
    return body(args->dir, args->count);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
    return 2;
  }
}

}  // namespace navbus::bench
