#!/usr/bin/env python3
"""The GNSS fixes' innovations (innovations.csv of `navbus offline --recording R --filter F
--innovations -o DIR` or of `navbus benchmark real-car`) as the statistics a fix error model is
read from: per row the mean normalized innovation squared (about 1 when the filter's covariance
and R explain it), and for the horizontal position innovation along and across the track, and
the vertical one, a first-order Gauss-Markov fit of its autocovariance at lags of 0.25 s and
more (the white part of the fix's noise only adds at lag 0): sigma^2 = C(first lag) and the
correlation time where C falls to 1/e of it. Run it on a filter without the fix's error states
(ekf.fix_position_error_* off), whose innovations still carry the correlated error.

The first --settle-s seconds (5) after the start and after every gap in the fixes are left out:
there the innovations carry the drift of the gap, not the fix's error.

usage: fix_innovations.py innovations.csv [--max-lag-s 60] [--settle-s 5]
"""
import argparse
import csv
import math
import sys

import numpy as np


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{path}: no fused fixes")
    cols = {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}
    return cols


def segments(t, max_gap_s):
    """Index ranges of contiguous fixes (no gap above max_gap_s)."""
    breaks = np.where(np.diff(t) > max_gap_s)[0] + 1
    edges = np.concatenate(([0], breaks, [len(t)]))
    return [(a, b) for a, b in zip(edges[:-1], edges[1:]) if b - a > 1]


def autocovariance(x, t, period_s, max_lag):
    """C(k period) over the contiguous segments, each segment's mean removed."""
    sums = np.zeros(max_lag + 1)
    counts = np.zeros(max_lag + 1)
    for a, b in segments(t, 1.5 * period_s):
        y = x[a:b] - x[a:b].mean()
        for k in range(min(max_lag, b - a - 1) + 1):
            sums[k] += np.dot(y[: len(y) - k], y[k:])
            counts[k] += len(y) - k
    with np.errstate(invalid="ignore"):
        return sums / counts


def gauss_markov(c, period_s):
    """sigma and correlation time of a first-order Gauss-Markov process from C at lags >= 1."""
    if not c[1] > 0.0:
        return 0.0, 0.0
    below = np.where(c[1:] < c[1] / math.e)[0]
    tau = (below[0] + 1) * period_s if below.size else float("nan")
    return math.sqrt(c[1]), tau


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("innovations")
    p.add_argument("--max-lag-s", type=float, default=60.0)
    p.add_argument("--settle-s", type=float, default=5.0)
    a = p.parse_args()
    c = read(a.innovations)
    t = c["gpst_s"]
    settled = np.zeros(len(t), dtype=bool)
    for lo, hi in segments(t, 1.0):
        settled[lo:hi] = t[lo:hi] >= t[lo] + a.settle_s
    c = {k: v[settled] for k, v in c.items()}
    t = c["gpst_s"]
    period = float(np.median(np.diff(t)))
    print(f"{len(t)} fused fixes ({(~settled).sum()} left out while the filter settled), "
          f"every {period:.3f} s")
    print("mean NIS per row       north   east    down")
    for name, inn, sig, unit in (("position", "pos_", "sigma_pos_", "_m"),
                                 ("velocity", "vel_inn_", "sigma_vel_", "_mps")):
        nis = [np.mean((c[inn + ax + unit] / c[sig + ax + unit]) ** 2) for ax in ("n", "e", "d")]
        print(f"  {name:10s}         " + "  ".join(f"{v:5.2f}" for v in nis))
    moving = (c["along_track_m"] != 0.0) | (c["cross_track_m"] != 0.0)
    print("position innovation   mean [m]  std [m]  Gauss-Markov sigma [m]  correlation time [s]")
    max_lag = int(a.max_lag_s / period)
    for name, x, m in (("along track", c["along_track_m"], moving),
                       ("across track", c["cross_track_m"], moving),
                                      ("down", c["pos_d_m"], np.ones_like(moving))):
        cov = autocovariance(x[m], t[m], period, max_lag)
        sigma, tau = gauss_markov(cov, period)
        print(f"  {name:13s} {x[m].mean():9.4f} {x[m].std():8.4f} {sigma:23.4f} {tau:21.1f}")
    flagged = c["consistent"] == 0
    print(f"fixes fused while the consistency monitor alarmed: {flagged.sum()} "
          f"({100.0 * flagged.mean():.1f} %)")


if __name__ == "__main__":
    main()
