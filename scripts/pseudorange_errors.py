#!/usr/bin/env python3
"""Each satellite's pseudorange error against a reference trajectory: the sigma and correlation
time for the filter's ekf.pseudorange_error_sigma_m and ekf.pseudorange_error_correlation_time_s.

Usage: pseudorange_errors.py RECORDING_DIR [--max-gap-s 1.0]
RECORDING_DIR holds navbus_gnss_observations.csv and navbus_gnss_fix.csv (RTK fixes as the
reference), as `navbus import DATASET -o DIR` or `navbus benchmark real-data` write them.

For each epoch with a reference fix within 10 ms (fixed solutions only: position sigma <= 5 cm),
the residual of satellite i is its corrected pseudorange minus its range from the reference
antenna. The receiver clock is common to all satellites and is what the filter's clock state
takes, so the epoch's mean residual is removed; with N satellites that also removes 1/N of each
satellite's own error, which the sigma is scaled back for (sqrt(N / (N - 1))). The correlation
time is the lag at which each satellite's residual autocorrelation first falls below 1/e; where
it never does within the satellite's track, the track's length is a lower bound (printed as
">=").
"""
import argparse
import csv
import math
import sys
from collections import defaultdict

import numpy as np


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("recording")
    ap.add_argument("--max-gap-s", type=float, default=1.0,
                    help="a satellite's track ends where its epochs are further apart")
    args = ap.parse_args()
    try:
        obs = read_rows(f"{args.recording}/navbus_gnss_observations.csv")
        fixes = read_rows(f"{args.recording}/navbus_gnss_fix.csv")
    except OSError as e:
        sys.exit(f"pseudorange_errors.py: {e}")
    ref = {}
    for r in fixes:
        if r["valid"] == "1" and float(r["pos_sigma_ned_m[0]"]) <= 0.05:
            ref[int(r["time_gps_ns"])] = np.array([float(r[f"pos_ecef_m[{i}]"]) for i in range(3)])
    ref_times = np.array(sorted(ref))
    if ref_times.size == 0:
        sys.exit("pseudorange_errors.py: no fixed reference epochs in navbus_gnss_fix.csv")
    epochs = defaultdict(list)
    for r in obs:
        if r["satellites.valid"] != "1":
            continue
        epochs[int(r["time_gps_ns"])].append(r)
    series = defaultdict(list)  # sv -> [(t_s, residual)]
    used = 0
    for t, sats in sorted(epochs.items()):
        j = np.searchsorted(ref_times, t)
        near = [k for k in (j - 1, j) if 0 <= k < ref_times.size]
        k = min(near, key=lambda k: abs(ref_times[k] - t))
        if abs(ref_times[k] - t) > 10_000_000 or len(sats) < 2:
            continue
        x = ref[ref_times[k]]
        res = {}
        for s in sats:
            p = np.array([float(s[f"satellites.sat_pos_ecef_m[{i}]"]) for i in range(3)])
            rho = float(s["satellites.pseudorange_m"]) + float(s["satellites.sat_clock_correction_m"])
            res[int(s["satellites.sv_id"])] = rho - np.linalg.norm(p - x)
        mean = sum(res.values()) / len(res)
        scale = math.sqrt(len(res) / (len(res) - 1))
        for sv, v in res.items():
            series[sv].append((t * 1e-9, (v - mean) * scale))
        used += 1
    print(f"{used} epochs against fixed reference positions")
    print("  sv   epochs  track [s]  RMS [m]  mean [m]  std about the mean [m]  "
          "its correlation time [s]")
    sigmas = []
    for sv in sorted(series):
        ts = np.array([p[0] for p in series[sv]])
        v = np.array([p[1] for p in series[sv]])
        if v.size < 10:
            continue
        dt = np.median(np.diff(ts))
        sigma = math.sqrt(np.mean(v ** 2))  # RMS about 0: the error itself, mean included
        c = v - v.mean()
        ac = np.correlate(c, c, "full")[c.size - 1:] / (c @ c)
        below = np.nonzero(ac < 1 / math.e)[0]
        track = ts[-1] - ts[0]
        tau = f"{below[0] * dt:8.1f}" if below.size else f">= {track:5.0f}"
        print(f"  {sv:3d} {v.size:7d} {track:10.1f} {sigma:8.2f} {v.mean():9.2f} {v.std():23.2f}  {tau}")
        sigmas.append(sigma)
    if sigmas:
        print(f"RMS over satellites: sigma {math.sqrt(np.mean(np.square(sigmas))):.2f} m")


if __name__ == "__main__":
    main()
