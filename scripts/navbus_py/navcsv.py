"""Reading navbus CSV files by their column names (see the README's CSV section), and the
navigation error of recorded solutions against the simulator's truth. Used by the demo summary
and the figure commands."""
import csv
import math

import yaml

# WGS84
_A = 6378137.0
_E2 = 6.69437999014e-3


def read_csv(path):
    """Rows of a CSV file as dicts keyed by the header's column names."""
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def vector(row, name, n=3):
    """The n elements name[0] ... name[n-1] of a row."""
    return [float(row[f"{name}[{i}]"]) for i in range(n)]


def _merge(base, over):
    """`over` onto `base` as the tools do: maps merge key by key, anything else replaces."""
    if not isinstance(base, dict) or not isinstance(over, dict):
        return over
    out = dict(base)
    for k, v in over.items():
        out[k] = _merge(base[k], v) if k in base else v
    return out


def load_scenario(path):
    """The scenario YAML with `extends` resolved (relative to the file, or absolute), merged as
    the tools merge it."""
    import os
    with open(path) as f:
        s = yaml.safe_load(f)
    if "extends" in s:
        base = load_scenario(os.path.join(os.path.dirname(path), s.pop("extends")))
        s = _merge(base, s)
    return s


def seconds(time_gps_ns, start_ns):
    return (int(time_gps_ns) - start_ns) * 1e-9


def ned_error(sol, truth):
    """Position error (solution - truth) [m, N E D] from geodetic latitude, longitude, height."""
    lat, lon, h = float(sol["latitude_rad"]), float(sol["longitude_rad"]), float(sol["height_m"])
    lat_t, lon_t, h_t = (float(truth["latitude_rad"]), float(truth["longitude_rad"]),
                         float(truth["height_m"]))
    s = math.sin(lat_t)
    n_radius = _A / math.sqrt(1 - _E2 * s * s)
    m_radius = _A * (1 - _E2) / (1 - _E2 * s * s) ** 1.5
    return [(lat - lat_t) * (m_radius + h_t), (lon - lon_t) * (n_radius + h_t) * math.cos(lat_t),
            -(h - h_t)]


def norm(v):
    return math.sqrt(sum(x * x for x in v))


def rms(values):
    return math.sqrt(sum(x * x for x in values) / len(values)) if values else float("nan")
