#!/usr/bin/python3
"""Figures from navbus CSV files (matplotlib, Debian's python3-matplotlib).

  plot_navbus.py errors OFFLINE_DIR -o OUT_DIR [--scenario YAML]
      position, velocity and attitude error with the filter's 3-sigma envelope (error.csv of
      `navbus offline`), decisions marked when decisions.csv is there -> errors.png
  plot_navbus.py compare WITH_DIR WITHOUT_DIR -o OUT_DIR [--scenario YAML]
      3-D position error with and without the fault manager (two `navbus offline` runs of the
      same scenario) -> with_without_fault_manager.png
  plot_navbus.py spectrum RAW_CSV --before T0 --after T1 --axis x -o OUT_DIR [--lines F F F]
      amplitude spectrum of one accelerometer from a `navbus-sensor-sim --files` imu_raw.csv
      over 0.5 s before T0 and after T1 [s from the first sample], dither lines marked
      -> spectrum_<axis>.png
  plot_navbus.py glr OFFLINE_DIR -o OUT_DIR [--scenario YAML]
      the GLR's largest statistic per epoch against its threshold h (glr.csv of `navbus offline`
      or `navbus rinex` with --fault-manager), detections marked -> glr.png
  plot_navbus.py montecarlo CSV_DIR -o OUT_DIR
      from `navbus montecarlo --csv CSV_DIR`: average NEES per epoch of each configuration with
      its 95 % band -> nees.png; with --fault-manager, the detection delays after the injected
      fault, one histogram per configuration -> detection_delay.png
  plot_navbus.py latency [--raw PING_CSV] [--e2e IMU_CSV] -o OUT_DIR
      latency histogram and CDF from `navbus latency ping --csv` (round trips: the raw two
      hops) and `navbus latency imu --csv` (increment -> low-latency output / deterministic
      solution) -> latency.png
  With --scenario, times are seconds from the scenario's start (timing.start); without, from
  the first row of the file.
  plot_navbus.py realcar BENCH_DIR -o OUT_DIR [--name NAME]
      from `navbus benchmark real-car ... -o BENCH_DIR [--smooth]` (or `real-data`): the
      antenna's trajectory with the GNSS outages marked, and per outage the horizontal error
      against the filter's 3-sigma (and the smoother's, with --smooth) -> NAME.png (default
      real_car). A benchmark run without outages (no outages.csv) gives the trajectory and the
      horizontal error of every judged epoch against 3-sigma, per run (filter, spp, smoothed).
  plot_navbus.py triplex SCENARIO LANES_DIR SINGLE_DIR -o OUT_DIR
      the triplex demo (scripts/demo_triplex.sh): the parity test's statistics against their
      thresholds (parity.csv), the published lane with the switch and its reset deltas
      (solution.csv, lanes.csv), and the horizontal position error of the lanes' published
      solution beside a single-lane filter on the faulty unit's data -> triplex.png
  plot_navbus.py demo SCENARIO DEMO_DIR -o OUT_DIR
      the main demo's figures (errors, with/without the fault manager, GLR statistic) from
      scripts/demo.sh's output directory
"""
import argparse
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(__file__))
from navbus_py.navcsv import load_scenario, read_csv, vector  # noqa: E402

AXES = ("north", "east", "down")


def _save(fig, out_dir, name):
    fig.tight_layout()
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, name)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _time_s(rows, start_ns):
    return np.array([(int(r["time_gps_ns"]) - start_ns) * 1e-9 for r in rows])


def _mark_decisions(ax, decisions, start_ns):
    for d in decisions:
        if d["event"] != "FAULT_DETECTED":
            continue
        t = (int(d["time_gps_ns"]) - start_ns) * 1e-9
        ax.axvline(t, color="tab:red", lw=0.8, ls="--")


def errors(offline_dir, out_dir, start_ns=None, title=""):
    rows = read_csv(os.path.join(offline_dir, "error.csv"))
    start_ns = start_ns if start_ns is not None else int(rows[0]["time_gps_ns"])
    t = _time_s(rows, start_ns)
    decisions_path = os.path.join(offline_dir, "decisions.csv")
    decisions = read_csv(decisions_path) if os.path.exists(decisions_path) else []
    fig, axes = plt.subplots(3, 3, figsize=(13, 8), sharex=True)
    blocks = (("pos_err_ned_m", "pos_sigma_ned_m", "position error [m]", 1.0),
              ("vel_err_ned_mps", "vel_sigma_ned_mps", "velocity error [m/s]", 1.0),
              ("att_err_ned_rad", "att_sigma_ned_rad", "attitude error [mrad]", 1e3))
    for row_i, (err, sig, label, scale) in enumerate(blocks):
        e = np.array([vector(r, err) for r in rows]) * scale
        s = np.array([vector(r, sig) for r in rows]) * scale
        for k in range(3):
            ax = axes[row_i][k]
            ax.fill_between(t, -3 * s[:, k], 3 * s[:, k], color="tab:blue", alpha=0.2,
                            label="filter 3-sigma")
            ax.plot(t, e[:, k], color="black", lw=0.8, label="error")
            _mark_decisions(ax, decisions, start_ns)
            ax.set_ylabel(f"{AXES[k]} {label}", fontsize=8)
            ax.grid(alpha=0.3)
            if row_i == 2:
                ax.set_xlabel("time [s]")
    axes[0][0].legend(fontsize=8, loc="upper left")
    fig.suptitle(title or f"navigation error and 3-sigma envelope ({offline_dir}); "
                 "dashed: fault decisions", fontsize=10)
    return _save(fig, out_dir, "errors.png")


def compare(with_dir, without_dir, out_dir, start_ns=None):
    fig, ax = plt.subplots(figsize=(10, 5))
    for d, label, color in ((without_dir, "without the fault manager", "tab:red"),
                            (with_dir, "with the fault manager (decisions -> commands)",
                             "tab:green")):
        rows = read_csv(os.path.join(d, "error.csv"))
        s0 = start_ns if start_ns is not None else int(rows[0]["time_gps_ns"])
        t = _time_s(rows, s0)
        e = np.linalg.norm(np.array([vector(r, "pos_err_ned_m") for r in rows]), axis=1)
        ax.semilogy(t, np.maximum(e, 1e-3), color=color, lw=1.0, label=label)
        if d == with_dir:
            s = np.linalg.norm(np.array([vector(r, "pos_sigma_ned_m") for r in rows]), axis=1)
            ax.semilogy(t, 3 * s, color="tab:blue", lw=0.8, ls=":", label="3-sigma (3-D), with")
            decisions_path = os.path.join(d, "decisions.csv")
            if os.path.exists(decisions_path):
                _mark_decisions(ax, read_csv(decisions_path), s0)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("3-D position error [m]")
    ax.set_title("the same data with and without fault exclusion / reconfiguration "
                 "(dashed: decisions)", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    return _save(fig, out_dir, "with_without_fault_manager.png")


def _amplitude(x, rate):
    n = len(x)
    w = np.hanning(n + 1)[:-1]
    spec = np.abs(np.fft.rfft((x - x.mean()) * w)) * 2 / w.sum()
    return np.fft.rfftfreq(n, 1 / rate), spec


def spectrum(raw_csv, before, after, axis, out_dir, lines=(373, 441, 409)):
    rows = read_csv(raw_csv)
    t0 = int(rows[0]["time_gps_ns"])
    t = np.array([(int(r["time_gps_ns"]) - t0) * 1e-9 for r in rows])
    x = np.array([float(r[f"specific_force_{axis}_mps2"]) for r in rows])
    rate = 1.0 / np.median(np.diff(t))
    fig, ax = plt.subplots(figsize=(10, 5))
    for t_start, label, color in ((before - 0.5, f"{before - 0.5:.1f}-{before:.1f} s (healthy)",
                                   "tab:blue"),
                                  (after, f"{after:.1f}-{after + 0.5:.1f} s (stuck)", "tab:red")):
        sel = (t >= t_start) & (t < t_start + 0.5)
        if sel.sum() < 16:
            continue
        f, a = _amplitude(x[sel], rate)
        # A stuck output has no spectrum at all: drawn at 1e-5 mg, the floor of the plot.
        ax.semilogy(f, np.maximum(a / 9.80665e-3, 1e-5), color=color, lw=0.8, label=label)
    for line in lines:
        ax.axvline(line, color="gray", ls="--", lw=0.8)
    ax.axvspan(300, 1200, color="tab:green", alpha=0.06, label="search band 300-1200 Hz")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(f"accelerometer {axis} amplitude [mg]")
    ax.set_title(f"raw accelerometer {axis} spectrum before and after a stuck fault "
                 f"(dashed: dither lines {', '.join(str(int(v)) for v in lines)} Hz)", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    return _save(fig, out_dir, f"spectrum_{axis}.png")


def glr(offline_dir, out_dir, start_ns=None, title=""):
    rows = read_csv(os.path.join(offline_dir, "glr.csv"))
    if not rows:
        raise SystemExit(f"{offline_dir}/glr.csv has no epochs (was the GLR enabled?)")
    start_ns = start_ns if start_ns is not None else int(rows[0]["time_gps_ns"])
    t = _time_s(rows, start_ns)
    stat = np.array([float(r["statistic"]) for r in rows])
    h = np.array([float(r["threshold"]) for r in rows])
    hit = np.array([r["detected"] == "1" for r in rows])
    fig, ax = plt.subplots(figsize=(10, 5))
    # The statistic is >= 0 and spans decades: a log axis with a floor keeps the quiet part
    # visible next to a detection.
    floor = 0.1
    ax.semilogy(t, np.maximum(stat, floor), color="black", lw=0.8, label="GLR statistic l")
    ax.semilogy(t, h, color="tab:red", lw=1.0, ls="--", label="threshold h")
    if hit.any():
        ax.semilogy(t[hit], stat[hit], "v", color="tab:red", ms=8, label="detection (l >= h)")
        ago = np.array([int(r["onset_epochs_ago"]) for r in rows])
        for n, i in enumerate(np.flatnonzero(hit)):
            ax.annotate(f"{t[i]:.1f} s", (t[i], stat[i]), textcoords="offset points",
                        xytext=(4, 8), fontsize=8, color="tab:red")
            # The fault began after epoch theta - 1 (seed 000's onset estimate).
            j = i - ago[i] - 1
            if j >= 0:
                ax.axvline(t[j], color="tab:orange", ls=":", lw=1.2,
                           label="estimated onset (after)" if n == 0 else None)
    ax.set_xlabel("time [s]")
    ax.set_ylim(bottom=floor, top=max(stat.max(), h.max()) * 3)
    ax.set_ylabel("largest GLR statistic over onsets and hypotheses")
    ax.set_title(title or f"GLR fault detection ({offline_dir})", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8, loc="upper right")
    return _save(fig, out_dir, "glr.png")


def _by_configuration(rows):
    out = {}
    for r in rows:
        out.setdefault(r["configuration"], []).append(r)
    return out


def montecarlo(csv_dir, out_dir):
    paths = []
    groups = _by_configuration(read_csv(os.path.join(csv_dir, "nees.csv")))
    fig, ax = plt.subplots(figsize=(10, 5))
    spread = [float(r["nees9_mean"]) for rows in groups.values() for r in rows]
    if spread and max(spread) > 20 * max(min(spread), 1e-9):
        ax.set_yscale("log")  # inconsistent configurations reach decades above the band
    for k, (label, rows) in enumerate(groups.items()):
        t = np.array([float(r["time_s"]) for r in rows])
        nees = np.array([float(r["nees9_mean"]) for r in rows])
        lo, hi = float(rows[0]["band_low"]), float(rows[0]["band_high"])
        runs = rows[0]["runs"]
        color = f"C{k}"
        inside = np.mean((nees >= lo) & (nees <= hi)) * 100
        ax.plot(t, nees, color=color, lw=0.8,
                label=f"{label}: mean {nees.mean():.2f}, {inside:.0f} % of epochs in band")
        ax.axhspan(lo, hi, color=color, alpha=0.12,
                   label=f"95 % band of the average over {runs} runs [{lo:.2f}, {hi:.2f}]")
    ax.axhline(9, color="gray", lw=0.8, ls=":", label="expected value 9")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("average NEES (position, velocity, attitude; 9 dof)")
    ax.set_title(f"Monte Carlo consistency ({csv_dir}/nees.csv)", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    paths.append(_save(fig, out_dir, "nees.png"))
    faults_path = os.path.join(csv_dir, "faults.csv")
    if not os.path.exists(faults_path):
        return paths
    groups = _by_configuration(read_csv(faults_path))
    fig, axes = plt.subplots(1, len(groups), figsize=(5 * len(groups), 4.5), squeeze=False)
    for ax, (label, rows) in zip(axes[0], groups.items()):
        delays = np.array([float(r["delay_s"]) for r in rows if r["detected"] == "1"])
        missed = sum(1 for r in rows if r["detected"] != "1")
        fault_s = float(rows[0]["fault_s"])
        if len(delays):
            # Detections happen at measurement epochs: one bin per epoch spacing.
            u = np.unique(delays)
            step = np.min(np.diff(u)) if len(u) > 1 else 1.0
            if (u[-1] - u[0]) / step > 60:
                step = (u[-1] - u[0]) / 30
            ax.hist(delays, bins=np.arange(u[0] - step / 2, u[-1] + step, step),
                    color="tab:blue", edgecolor="black")
            ax.axvline(np.median(delays), color="tab:red", ls="--",
                       label=f"median {np.median(delays):.1f} s")
            ax.legend(fontsize=8)
        ax.set_xlabel(f"detection time after the fault at {fault_s:.0f} s [s]")
        ax.set_ylabel("runs")
        ax.set_title(f"{label}\n{len(delays)} detected, {missed} missed of {len(rows)}",
                     fontsize=9)
        ax.grid(alpha=0.3)
    paths.append(_save(fig, out_dir, "detection_delay.png"))
    return paths


def latency(raw_csv, e2e_csv, out_dir):
    series = []
    if raw_csv:
        series.append(("raw Fast DDS, two hops (round trip)",
                       [int(r["round_trip_ns"]) for r in read_csv(raw_csv)]))
    if e2e_csv:
        rows = read_csv(e2e_csv)
        series.append(("IMU -> low-latency output",
                       [int(r["low_latency_ns"]) for r in rows if int(r["low_latency_ns"]) >= 0]))
        series.append(("IMU -> deterministic solution",
                       [int(r["solution_ns"]) for r in rows if int(r["solution_ns"]) >= 0]))
    series = [(name, np.array(v) * 1e-3) for name, v in series if v]
    if not series:
        raise SystemExit("latency: give --raw and/or --e2e with at least one sample")
    fig, (hist, cdf) = plt.subplots(1, 2, figsize=(11, 4))
    hi = max(np.percentile(v, 99.5) for _, v in series)
    bins = np.linspace(0.0, hi, 80)
    for name, v in series:
        med, p99 = np.percentile(v, 50), np.percentile(v, 99)
        label = f"{name}: median {med:.0f}, p99 {p99:.0f} us (n = {len(v)})"
        hist.hist(np.clip(v, 0, hi), bins=bins, histtype="step", label=label)
        xs = np.sort(v)
        cdf.plot(xs, np.arange(1, len(xs) + 1) / len(xs), label=name)
    hist.set_xlabel("latency [us] (beyond the 99.5th percentile piled in the last bin)")
    hist.set_ylabel("samples")
    hist.legend(fontsize=7)
    cdf.set_xscale("log")
    cdf.set_xlabel("latency [us]")
    cdf.set_ylabel("fraction of samples")
    cdf.grid(True, which="both", lw=0.3)
    cdf.legend(fontsize=7)
    fig.suptitle("navbus latency (write -> received)")
    return _save(fig, out_dir, "latency.png")


def _local_en(lat_deg, lon_deg, lat0_deg, lon0_deg):
    """East and north [m] from a reference point (a local plane, metres-scale accuracy)."""
    radius = 6378137.0
    east = np.radians(lon_deg - lon0_deg) * radius * math.cos(math.radians(lat0_deg))
    north = np.radians(lat_deg - lat0_deg) * radius
    return east, north


RUN_COLOURS = {"filter": "tab:blue", "smoothed": "tab:green", "spp": "tab:orange"}


def _trajectory(bench_dir):
    """Times [GPS s of week] and east, north [m] of the filter's antenna from solution.csv."""
    sol = read_csv(os.path.join(bench_dir, "solution.csv"))
    t = np.array([float(r["gpst_s"]) for r in sol])
    lat = np.array([float(r["lat_deg"]) for r in sol])
    lon = np.array([float(r["lon_deg"]) for r in sol])
    east, north = _local_en(lat, lon, lat[0], lon[0])
    return t, east, north


def _runs(epochs):
    return sorted({r["run"] for r in epochs}, key=lambda x: x != "filter")


def realdata(bench_dir, out_dir, name):
    """A benchmark run without outages: trajectory, and every judged epoch's horizontal error
    against 3 sigma, one panel per run (the filter, single point positioning, the smoother)."""
    t, east, north = _trajectory(bench_dir)
    epochs = read_csv(os.path.join(bench_dir, "errors.csv"))
    runs = _runs(epochs)
    fig = plt.figure(figsize=(15, 5.5))
    grid = fig.add_gridspec(len(runs), 2, width_ratios=[1, 1.6])
    ax = fig.add_subplot(grid[:, 0])
    ref = [r for r in epochs if r["run"] == runs[0]]
    sol = read_csv(os.path.join(bench_dir, "solution.csv"))
    lat0, lon0 = float(sol[0]["lat_deg"]), float(sol[0]["lon_deg"])
    ref_e, ref_n = _local_en(np.array([float(r["ref_lat_deg"]) for r in ref]),
                             np.array([float(r["ref_lon_deg"]) for r in ref]), lat0, lon0)
    ax.plot(ref_e, ref_n, ".", color="k", ms=2.5, label="reference (receiver's fixed RTK)")
    ax.plot(east, north, color=RUN_COLOURS["filter"], lw=0.8, label="filter (causal), antenna")
    ax.plot(east[0], north[0], "o", color=RUN_COLOURS["filter"], label="filter's first solution")
    ax.set_xlabel("east [m]")
    ax.set_ylabel("north [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(loc="best", fontsize=8)
    ax.set_title(f"{name}: trajectory")
    t0 = min(float(r["gpst_s"]) for r in epochs)
    first = None
    for i, run in enumerate(runs):
        sel = [r for r in epochs if r["run"] == run]
        ts = np.array([float(r["gpst_s"]) - t0 for r in sel])
        err = np.array([float(r["error_h_m"]) for r in sel])
        sig = np.array([float(r["sigma_h_m"]) for r in sel])
        a = fig.add_subplot(grid[i, 1], sharex=first)
        first = first or a
        c = RUN_COLOURS.get(run, "k")
        rms = math.sqrt(float(np.mean(err**2))) if len(err) else float("nan")
        inside = 100.0 * float(np.mean(err <= 3 * sig)) if len(err) else float("nan")
        a.plot(ts, err, color=c, lw=1.0,
               label=f"{run}: horizontal error (RMS {rms:.2f} m, {len(err)} epochs)")
        a.plot(ts, 3 * sig, color=c, lw=0.9, ls="--",
               label=f"{run}: own 3 sigma ({inside:.1f} % inside)")
        a.set_ylabel("horizontal [m]")
        a.grid(True, lw=0.3)
        a.legend(fontsize=7, loc="upper right")
        a.set_ylim(bottom=0.0)
        if i == len(runs) - 1:
            a.set_xlabel("s from the first judged epoch")
    fig.suptitle(f"{name}: horizontal error against the receiver's fixed RTK epochs")
    return _save(fig, out_dir, f"{name}.png")


def realcar(bench_dir, out_dir, name="real_car"):
    if not os.path.exists(os.path.join(bench_dir, "outages.csv")):
        return realdata(bench_dir, out_dir, name)
    outages = read_csv(os.path.join(bench_dir, "outages.csv"))
    epochs = read_csv(os.path.join(bench_dir, "errors.csv"))
    t, east, north = _trajectory(bench_dir)
    runs = _runs(epochs)
    n = len(outages)
    cols = 5
    rows = (n + cols - 1) // cols
    fig = plt.figure(figsize=(16, 4.2 + 2.4 * rows))
    grid = fig.add_gridspec(1 + rows, cols, height_ratios=[2.2] + [1] * rows)
    ax = fig.add_subplot(grid[0, :3])
    ax.plot(east, north, color="0.6", lw=0.8, label="filter (causal), antenna")
    for o in outages:
        inside = (t >= float(o["start_sow"])) & (t < float(o["end_sow"]))
        ax.plot(east[inside], north[inside], color="tab:red", lw=2.0)
        if inside.any():
            ax.annotate(o["outage"], (east[inside][0], north[inside][0]), fontsize=8)
    ax.plot([], [], color="tab:red", lw=2.0, label="GNSS withheld (outages, numbered)")
    ax.set_xlabel("east [m]")
    ax.set_ylabel("north [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(loc="best", fontsize=8)
    ax.set_title(f"{name}: trajectory and GNSS outages")
    colours = RUN_COLOURS
    bars = fig.add_subplot(grid[0, 3:])
    labels = [o["outage"] for o in outages]
    x = np.arange(len(labels))
    width = 0.8 / len(runs)
    for j, run in enumerate(runs):
        table = outages if run == "filter" else read_csv(
            os.path.join(bench_dir, f"{run}_outages.csv"))
        bars.bar(x + j * width, [float(o["end_error_m"]) for o in table], width,
                 color=colours.get(run, "k"), label=f"{run}: at the end")
        bars.scatter(x + j * width, [float(o["max_error_m"]) for o in table], marker="_", s=80,
                     color="k")
    bars.scatter([], [], marker="_", color="k", label="largest inside")
    bars.set_xticks(x + 0.4 - width / 2, labels)
    bars.set_xlabel("outage")
    bars.set_ylabel("horizontal error [m]")
    bars.legend(fontsize=8)
    bars.set_title("error per outage")
    for i, o in enumerate(outages):
        a = fig.add_subplot(grid[1 + i // cols, i % cols])
        start = float(o["start_sow"])
        for run in runs:
            sel = [r for r in epochs if r["run"] == run and r["outage"] == o["outage"]]
            ts = np.array([float(r["gpst_s"]) - start for r in sel])
            err = np.array([float(r["error_h_m"]) for r in sel])
            sig = np.array([float(r["sigma_h_m"]) for r in sel])
            c = colours.get(run, "k")
            a.plot(ts, err, color=c, lw=1.2, label=f"{run}: error")
            a.plot(ts, 3 * sig, color=c, lw=0.9, ls="--", label=f"{run}: 3 sigma")
        a.set_title(f"outage {o['outage']}", fontsize=9)
        a.set_xlabel("s into the outage", fontsize=8)
        if i % cols == 0:
            a.set_ylabel("horizontal [m]", fontsize=8)
        a.tick_params(labelsize=7)
        if i == 0:
            a.legend(fontsize=6)
    return _save(fig, out_dir, f"{name}.png")


def triplex(scenario_path, lanes_dir, single_dir, out_dir):
    start_ns = int(load_scenario(scenario_path)["timing"]["start"])
    decisions = read_csv(os.path.join(lanes_dir, "decisions.csv"))
    fig, axes = plt.subplots(3, 1, figsize=(11, 9), sharex=True)
    parity = read_csv(os.path.join(lanes_dir, "parity.csv"))
    t = _time_s(parity, start_ns)
    for key, color, label in (("gyro", "tab:blue", "gyros"),
                              ("accelerometer", "tab:orange", "accelerometers")):
        axes[0].semilogy(t, np.maximum([float(r[key + "_statistic"]) for r in parity], 1e-2),
                         color=color, lw=0.7, label=f"parity GLR statistic l, {label}")
    axes[0].axhline(float(parity[0]["gyro_threshold"]), color="black", ls=":",
                    label="threshold h (from P_fa)")
    _mark_decisions(axes[0], decisions, start_ns)
    axes[0].set_ylabel("largest l per 100 ms")
    axes[0].legend(fontsize=7, loc="upper left")
    sol = read_csv(os.path.join(lanes_dir, "solution.csv"))
    ts = _time_s(sol, start_ns)
    axes[1].step(ts, [int(r["lane_id"]) for r in sol], where="post", color="tab:green",
                 label="published lane (IMU sensor id)")
    switches = [r for i, r in enumerate(sol)
                if i > 0 and r["reset_count"] != sol[i - 1]["reset_count"]]
    for r in switches:
        ts0 = (int(r["time_gps_ns"]) - start_ns) * 1e-9
        d = vector(r, "reset_delta_pos_ned_m")
        a = np.linalg.norm(vector(r, "reset_delta_att_ned_rad")) * 1e3
        axes[1].annotate(f"switch {r['reset_count']}: reset deltas |dp| {np.linalg.norm(d):.3f} m,"
                         f" |dv| {np.linalg.norm(vector(r, 'reset_delta_vel_ned_mps')):.3f} m/s,"
                         f" |datt| {a:.1f} mrad", (ts0, int(r["lane_id"])), fontsize=8,
                         xytext=(-420, -30), textcoords="offset points")
    _mark_decisions(axes[1], decisions, start_ns)
    axes[1].set_ylabel("lane")
    axes[1].legend(fontsize=7, loc="lower left")
    for d, label, color in ((single_dir, "single lane on the faulty unit (no parity test)",
                             "tab:red"),
                            (lanes_dir, "lanes + parity test (published)", "tab:green")):
        rows = read_csv(os.path.join(d, "error.csv"))
        te = _time_s(rows, start_ns)
        e = np.array([vector(r, "pos_err_ned_m") for r in rows])
        axes[2].plot(te, np.hypot(e[:, 0], e[:, 1]), color=color, lw=0.8, label=label)
        if d == lanes_dir:
            s = np.array([vector(r, "pos_sigma_ned_m") for r in rows])
            axes[2].plot(te, 3 * np.hypot(s[:, 0], s[:, 1]), color="tab:blue", lw=0.7, ls=":",
                         label="3-sigma (horizontal), lanes")
    _mark_decisions(axes[2], decisions, start_ns)
    axes[2].set_ylabel("horizontal position error [m]")
    axes[2].set_xlabel("time [s]")
    axes[2].legend(fontsize=7, loc="upper left")
    for a in axes:
        a.grid(alpha=0.3, which="both")
    fig.suptitle("triplex IMUs: a slow gyro ramp on the filter's own unit; dashed: the parity "
                 "decision", fontsize=10)
    return _save(fig, out_dir, "triplex.png")


def demo(scenario_path, demo_dir, out_dir):
    start_ns = int(load_scenario(scenario_path)["timing"]["start"])
    paths = [errors(os.path.join(demo_dir, "offline"), out_dir, start_ns,
                    "demo: navigation error and 3-sigma envelope; dashed: fault decisions"),
             compare(os.path.join(demo_dir, "offline"),
                     os.path.join(demo_dir, "offline_without_fault_manager"), out_dir, start_ns),
             glr(os.path.join(demo_dir, "offline"), out_dir, start_ns,
                 "demo: GLR statistic on the filter's diagnostics against its threshold")]
    return paths


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    a = sub.add_parser("errors")
    a.add_argument("offline_dir")
    a.add_argument("-o", "--out", required=True)
    a = sub.add_parser("compare")
    a.add_argument("with_dir")
    a.add_argument("without_dir")
    a.add_argument("-o", "--out", required=True)
    a = sub.add_parser("spectrum")
    a.add_argument("raw_csv")
    a.add_argument("--before", type=float, required=True)
    a.add_argument("--after", type=float, required=True)
    a.add_argument("--axis", choices=("x", "y", "z"), default="x")
    a.add_argument("--lines", type=float, nargs=3, default=(373, 441, 409))
    a.add_argument("-o", "--out", required=True)
    a = sub.add_parser("glr")
    a.add_argument("offline_dir")
    a.add_argument("-o", "--out", required=True)
    a = sub.add_parser("montecarlo")
    a.add_argument("csv_dir")
    a.add_argument("-o", "--out", required=True)
    a = sub.add_parser("latency")
    a.add_argument("--raw", help="navbus latency ping --csv file")
    a.add_argument("--e2e", help="navbus latency imu --csv file")
    a.add_argument("-o", "--out", required=True)
    a = sub.add_parser("realcar")
    a.add_argument("bench_dir")
    a.add_argument("--name", default="real_car")
    a.add_argument("-o", "--out", required=True)
    a = sub.add_parser("triplex")
    a.add_argument("scenario")
    a.add_argument("lanes_dir")
    a.add_argument("single_dir")
    a.add_argument("-o", "--out", required=True)
    a = sub.add_parser("demo")
    a.add_argument("scenario")
    a.add_argument("demo_dir")
    a.add_argument("-o", "--out", required=True)
    for name in ("errors", "compare", "glr"):
        sub.choices[name].add_argument("--scenario", help="times from this scenario's start")
    args = p.parse_args()
    start_ns = (int(load_scenario(args.scenario)["timing"]["start"])
                if getattr(args, "scenario", None) and args.cmd != "demo" else None)
    if args.cmd == "errors":
        paths = [errors(args.offline_dir, args.out, start_ns)]
    elif args.cmd == "compare":
        paths = [compare(args.with_dir, args.without_dir, args.out, start_ns)]
    elif args.cmd == "spectrum":
        paths = [spectrum(args.raw_csv, args.before, args.after, args.axis, args.out, args.lines)]
    elif args.cmd == "glr":
        paths = [glr(args.offline_dir, args.out, start_ns)]
    elif args.cmd == "montecarlo":
        paths = montecarlo(args.csv_dir, args.out)
    elif args.cmd == "latency":
        paths = [latency(args.raw, args.e2e, args.out)]
    elif args.cmd == "realcar":
        paths = [realcar(args.bench_dir, args.out, args.name)]
    elif args.cmd == "triplex":
        paths = [triplex(args.scenario, args.lanes_dir, args.single_dir, args.out)]
    else:
        paths = demo(args.scenario, args.demo_dir, args.out)
    for path in paths:
        print(f"figure: {path}")


if __name__ == "__main__":
    main()
