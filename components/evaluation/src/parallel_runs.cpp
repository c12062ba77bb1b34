#include "navbus/evaluation/parallel_runs.hpp"

#include <fftw3.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <mutex>
#include <thread>

namespace navbus::evaluation {

void makeFftPlanningThreadSafe() {
  static std::once_flag once;
  std::call_once(once, [] { fftw_make_planner_thread_safe(); });
}

std::vector<OfflineResult> runInParallel(const std::vector<OfflineSetup>& setups,
                                         int threads_wanted, const std::string& label) {
  makeFftPlanningThreadSafe();
  const int runs = static_cast<int>(setups.size());
  std::vector<OfflineResult> results(setups.size());
  std::atomic<int> next{0}, done{0};
  std::mutex progress;
  auto worker = [&] {
    for (int i = next++; i < runs; i = next++) {
      results[static_cast<std::size_t>(i)] = runOffline(setups[static_cast<std::size_t>(i)]);
      const std::lock_guard<std::mutex> lock(progress);
      std::fprintf(stderr, "\r[%s] run %d/%d", label.c_str(), ++done, runs);
      std::fflush(stderr);
    }
  };
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  const int threads = std::min(runs, threads_wanted > 0 ? threads_wanted : static_cast<int>(hw));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  std::fprintf(stderr, "\n");
  return results;
}

}  // namespace navbus::evaluation
