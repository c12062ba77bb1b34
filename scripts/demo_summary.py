#!/usr/bin/python3
"""The main demo's summary: for each injected fault, the solution error before it, the
decision (detector, source, detection time, onset, magnitude), the command and the filter's
reconfiguration, and the error after it, next to the same run without the fault manager.

Reads the bus recording (navbus record: solutions, decisions, commands) and the truth of the
same scenario (navbus offline writes it; the simulator is deterministic), by column name.

usage: demo_summary.py SCENARIO.yaml RECORD_DIR TRUTH_DIR WITHOUT_FM_DIR
"""
import sys

sys.path.insert(0, __import__("os").path.dirname(__file__))
from navbus_py.navcsv import load_scenario, ned_error, norm, read_csv, rms, seconds  # noqa: E402


def errors(solutions, truth_by_time):
    """(t [s from start], 3-D position error [m], 3-D 1-sigma [m], mode, flags) per solution."""
    out = []
    for s in solutions:
        t = truth_by_time.get(s["time_gps_ns"])
        if t is None:
            continue
        sigma = norm([float(s[f"pos_sigma_ned_m[{i}]"]) for i in range(3)])
        out.append((int(s["time_gps_ns"]), norm(ned_error(s, t)), sigma, s["mode"],
                    int(s["active_fault_flags"])))
    return out


def integrity(solutions, truth_by_time):
    """One line: the protection levels of the recorded solutions against their true errors."""
    rows = [(s, truth_by_time[s["time_gps_ns"]]) for s in solutions
            if s.get("integrity") in ("AVAILABLE", "UNAVAILABLE") and s["time_gps_ns"] in truth_by_time]
    if not rows:
        return "integrity: no protection levels (no integrity block, or not tightly coupled)"
    hpl = sorted(float(s["horizontal_protection_level_m"]) for s, _ in rows)
    vpl = sorted(float(s["vertical_protection_level_m"]) for s, _ in rows)
    beyond = 0
    for s, t in rows:
        e = ned_error(s, t)
        beyond += norm(e[:2]) > float(s["horizontal_protection_level_m"]) or \
            abs(e[2]) > float(s["vertical_protection_level_m"])
    available = sum(1 for s, _ in rows if s["integrity"] == "AVAILABLE")
    return (f"integrity: {len(rows)} solutions with protection levels, {100 * available / len(rows):.1f} % "
            f"available; HPL median {hpl[len(hpl) // 2]:.1f} m, VPL median {vpl[len(vpl) // 2]:.1f} m; "
            f"true error beyond a level in {beyond}")


def window(errs, start_ns, t0, t1):
    sel = [e for e in errs if t0 <= seconds(e[0], start_ns) < t1]
    if not sel:
        return "no solutions"
    e = [x[1] for x in sel]
    three_sigma = 3 * sum(x[2] for x in sel) / len(sel)
    inside = sum(1 for x in sel if x[1] <= 3 * x[2])
    return (f"3-D position error RMS {rms(e):6.2f} m, max {max(e):7.2f} m; mean 3-sigma "
            f"{three_sigma:5.2f} m, {100 * inside / len(sel):3.0f} % of solutions inside it")


def describe_fault(f):
    if f["type"] == "pseudorange_ramp":
        return f"pseudorange ramp of {f['slope_mps']} m/s on sv {f['sv_id']}"
    if f["type"] == "sensor_stuck":
        return f"{f['sensor']} {f['axis']} stuck (constant output)"
    return f["type"]


def describe_decision(d, start_ns):
    what = d["source"] + (f" sv {d['sv_id']}" if d["source"] == "SATELLITE" else
                          f" axis {'xyz'[int(d['axis'])]}")
    text = (f"decision {d['decision_id']} at {seconds(d['time_gps_ns'], start_ns):6.2f} s: "
            f"{d['detector']} {d['event']} {what}, onset after "
            f"{seconds(d['onset_time_gps_ns'], start_ns):6.2f} s")
    if d["detector"] == "glr":
        unit = "m/s" if d["shape"] == "RAMP" else "m"
        text += (f", {d['shape'].lower()} magnitude {float(d['magnitude']):.2f} {unit} "
                 f"(l {float(d['test_statistic']):.1f} >= h {float(d['threshold']):.1f})")
    elif d["detector"] == "dither-fft":
        expected = " ".join(f"{float(d[f'dither_expected_frequency_hz[{i}]']):.0f}"
                            for i in range(3))
        text += (f": largest peak {float(d['dither_peak_frequency_hz']):.0f} Hz at "
                 f"{float(d['dither_peak_amplitude']):.1e} (a dither line must be within "
                 f"{float(d['dither_tolerance_hz']):.0f} Hz of {expected} Hz and reach "
                 f"{float(d['dither_min_amplitude']):.1e})")
    return text


def main(scenario_path, record_dir, truth_dir, without_dir):
    scenario = load_scenario(scenario_path)
    start_ns = int(scenario["timing"]["start"])
    duration = float(scenario["timing"]["duration_s"])
    truth = {r["time_gps_ns"]: r for r in read_csv(f"{truth_dir}/truth.csv")}
    bus = errors(read_csv(f"{record_dir}/navbus_nav_solution.csv"), truth)
    without = errors(read_csv(f"{without_dir}/solution.csv"), truth)
    decisions = read_csv(f"{record_dir}/navbus_fault_decision.csv")
    commands = read_csv(f"{record_dir}/navbus_filter_command.csv")
    faults = sorted(scenario.get("faults", []), key=lambda f: f["start_s"])
    undetected = 0

    print(f"scenario {scenario['name']}: {len(bus)} solutions recorded over {duration:.0f} s, "
          f"{len(decisions)} decisions, {len(commands)} commands")
    print(integrity(read_csv(f"{record_dir}/navbus_nav_solution.csv"), truth))
    for k, f in enumerate(faults):
        t_fault = float(f["start_s"])
        t_next = float(faults[k + 1]["start_s"]) if k + 1 < len(faults) else duration
        t_prev = float(faults[k - 1]["start_s"]) if k > 0 else 0.0
        print(f"\nfault {k + 1}: {describe_fault(f)}, injected at {t_fault:.1f} s")
        print(f"  before    ({max(t_prev, t_fault - 10):5.1f}-{t_fault:5.1f} s): "
              f"{window(bus, start_ns, max(t_prev, t_fault - 10), t_fault)}")
        found = [d for d in decisions if d["event"] == "FAULT_DETECTED" and
                 t_fault <= seconds(d["onset_time_gps_ns"], start_ns) + 2 and
                 seconds(d["time_gps_ns"], start_ns) < t_next]
        if not found:
            print("  NOT DETECTED")
            undetected += 1
            continue
        d = found[0]
        t_decided = seconds(d["time_gps_ns"], start_ns)
        print(f"  {describe_decision(d, start_ns)}")
        print(f"            detected {t_decided - t_fault:.2f} s after the fault")
        for c in commands:
            if c["decision_id"] == d["decision_id"]:
                what = f"sv {c['sv_id']} ({c['scope']})" if "SATELLITE" in c["kind"] else \
                    f"{c['sensor']} axis {'xyz'[int(c['axis'])]}"
                print(f"  command {c['command_id']}: {c['kind']} {what}")
        after = [e for e in bus if t_decided <= seconds(e[0], start_ns) < t_next]
        if after:
            # The mode and flags the filter settles in, and the first solution of the run of
            # solutions carrying them up to the next fault: with fast pacing the filter may be
            # ahead of the fault manager in data time when the command arrives (its state is
            # restored from the onset; solutions already published stay as they were).
            mode, flags = after[-1][3], after[-1][4]
            since = len(after)
            while since > 0 and (after[since - 1][3], after[since - 1][4]) == (mode, flags):
                since -= 1
            t_since = seconds(after[since][0], start_ns)
            print(f"  filter    mode {mode}, fault flags 0x{flags:04x} from {t_since:.2f} s on "
                  f"({t_since - t_decided:.2f} s of data after the decision time)")
        print(f"  after     ({t_decided + 1:5.1f}-{t_next:5.1f} s): "
              f"{window(bus, start_ns, t_decided + 1, t_next)}")
        print(f"  no fault manager, same data: {window(without, start_ns, t_decided + 1, t_next)}")
    lost = [d for d in decisions if d["event"] == "STREAM_LOST"]
    print(f"\nend of data: {len(lost)} stream-lost decisions (the simulator announces the end of "
          f"its streams; a crash would be reported)")
    return 1 if undetected or lost else 0


if __name__ == "__main__":
    if len(sys.argv) != 5:
        print(__doc__)
        sys.exit(2)
    sys.exit(main(*sys.argv[1:]))
