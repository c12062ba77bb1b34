// Offline runs on several threads (the Monte Carlo's workers), results in the setups' order.
#pragma once

#include <string>
#include <vector>

#include "navbus/evaluation/offline_runner.hpp"

namespace navbus::evaluation {

/// Runs every setup through runOffline, `threads_wanted` at a time (0: one per core), and
/// returns the results in the setups' order; each result is the one a run on its own gives.
/// Progress ("[label] run i/n") goes to stderr. Makes FFTW's planner safe for the threads
/// first: each run builds its own fault pipeline, whose dither monitor plans an FFT, and
/// FFTW's planner (unlike its execution) is not thread-safe by itself.
/// FFTW >= 3.3.5 (libfftw3_threads): serialises FFTW's planner behind a lock of its own, so that
/// plans (core::SpectrumAnalyzer) may be made and destroyed on any thread. Idempotent; call it
/// before threads that build fault pipelines start (runInParallel does).
void makeFftPlanningThreadSafe();

std::vector<OfflineResult> runInParallel(const std::vector<OfflineSetup>& setups,
                                         int threads_wanted, const std::string& label);

}  // namespace navbus::evaluation
