#!/usr/bin/python3
"""The triplex demo's summary (scripts/demo_triplex.sh): the parity decision, the lane switch with
its reset deltas, and the horizontal error of the lanes' published solution beside a single-lane
filter on the faulty unit's data, from the `navbus offline` directories and the bus recording.

  triplex_summary.py SCENARIO LANES_DIR SINGLE_DIR RECORD_DIR
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
from navbus_py.navcsv import load_scenario, read_csv, seconds, vector  # noqa: E402


def horizontal(rows, start_ns, after_s):
    """Largest horizontal error after `after_s` and the share of those epochs inside 3 sigma."""
    worst, inside, n = 0.0, 0, 0
    for r in rows:
        if seconds(r["time_gps_ns"], start_ns) < after_s:
            continue
        e = vector(r, "pos_err_ned_m")
        s = vector(r, "pos_sigma_ned_m")
        worst = max(worst, math.hypot(e[0], e[1]))
        inside += all(abs(e[i]) <= 3 * s[i] for i in range(3))
        n += 1
    return worst, 100.0 * inside / max(n, 1)


def main(scenario, lanes_dir, single_dir, record_dir):
    start_ns = int(load_scenario(scenario)["timing"]["start"])
    fault = load_scenario(scenario)["faults"][0]
    print(f"fault: {fault['type']} on IMU {fault['sensor_id']} {fault['sensor']} "
          f"{fault['axis']} from {fault['start_s']} s")
    for d in read_csv(os.path.join(lanes_dir, "decisions.csv")):
        print(f"decision {d['decision_id']} ({d['detector']}) at "
              f"{seconds(d['time_gps_ns'], start_ns):.2f} s: {d['source']} IMU {d['sensor_id']} "
              f"axis {'xyz'[int(d['axis'])]}, l {float(d['test_statistic']):.2f} >= h "
              f"{float(d['threshold']):.2f}, bias {float(d['magnitude']) / math.radians(1) * 3600:.3f}"
              f" deg/h ({seconds(d['time_gps_ns'], start_ns) - fault['start_s']:.1f} s after the "
              "ramp began)")
    sol = read_csv(os.path.join(lanes_dir, "solution.csv"))
    for prev, r in zip(sol, sol[1:]):
        if r["reset_count"] != prev["reset_count"]:
            dp = vector(r, "reset_delta_pos_ned_m")
            dv = vector(r, "reset_delta_vel_ned_mps")
            da = vector(r, "reset_delta_att_ned_rad")
            print(f"lane switch {r['reset_count']} at {seconds(r['time_gps_ns'], start_ns):.1f} s: "
                  f"IMU {prev['lane_id']} -> IMU {r['lane_id']}; reset deltas position "
                  f"[{dp[0]:.3f} {dp[1]:.3f} {dp[2]:.3f}] m, velocity "
                  f"[{dv[0]:.4f} {dv[1]:.4f} {dv[2]:.4f}] m/s, attitude "
                  f"{1e3 * math.sqrt(sum(x * x for x in da)):.2f} mrad")
    recorded = os.path.join(record_dir, "navbus_nav_solution.csv")
    if os.path.exists(recorded):
        bus = read_csv(recorded)
        same = len(bus) == len(sol) and all(
            b["lane_id"] == o["lane_id"] and b["reset_count"] == o["reset_count"]
            and b["latitude_rad"] == o["latitude_rad"] for b, o in zip(bus, sol))
        print(f"over the bus: {len(bus)} solutions recorded, lanes, counters and positions equal "
              f"to navbus offline: {'yes' if same else 'NO'}")
    t0 = float(fault["start_s"])
    for d, label in ((single_dir, "single lane on IMU 1, no parity test"),
                     (lanes_dir, "three lanes + parity test (published)")):
        worst, inside = horizontal(read_csv(os.path.join(d, "error.csv")), start_ns, t0)
        print(f"after the ramp began, {label}: largest horizontal error {worst:.2f} m, "
              f"{inside:.1f} % of epochs inside 3 sigma on every axis")


if __name__ == "__main__":
    main(*sys.argv[1:5])
