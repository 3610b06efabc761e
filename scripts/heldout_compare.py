#!/usr/bin/env python3
"""Issue 36's "Must show" for compare and verify, end to end: sessions from
the simulator (gravcal.simulate, the shipped configs/twelve_position.yaml:
raw counts, batch-means pose noise, 2 degree placement error), calibrated by
the full pipeline (gravcal.calibrate), tested by gravcal.compare and
gravcal.verify. Not part of the test suite (about a minute); the in-process
tests (tests/calibration_comparison_test.cc) check the same claims on pose
means. Numbers are in docs/workflows/compare.md.

The truth is held fixed across recordings: the simulator draws no sensor
error (sim_accel_bias/scale/misalignment 0), and every recording's raw
samples v0 are mapped to the truth v = U^-1 M0 v0 + b (M0 the simulator's
counts-to-m/s^2 scale), so a truth moved in one parameter is the same map
with that parameter moved, on new noise.

    PYTHONPATH=build/python /usr/bin/python3 scripts/heldout_compare.py [pairs]
"""
import os
import sys

import numpy as np

import gravcal

SOURCE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CONFIG = os.path.join(SOURCE, "configs", "twelve_position.yaml")
ZERO_TRUTH = {"sim_accel_bias": 0.0, "sim_accel_scale": 0.0, "sim_accel_misalignment": 0.0}
M0 = 9.80665 / 16384.0  # m/s^2 per count of the simulator's accelerometer
AXES = "xyz"


def base_truth():
    """A unit's (b in counts, U in m/s^2 per count, upper triangular)."""
    b = np.array([120.0, -80.0, 200.0])
    u = M0 * np.array([[1.01, 0.002, -0.003], [0.0, 0.995, 0.001], [0.0, 0.0, 1.004]])
    return b, u


def moved(truth, name, delta):
    b, u = truth[0].copy(), truth[1].copy()
    if name.startswith("bias_"):
        b[AXES.index(name[5])] += delta
    else:
        u[AXES.index(name[2]), AXES.index(name[3])] += delta
    return b, u


def recording(truth, seed, plan=None):
    """t, raw accelerometer (counts) of the truth on the simulator's noise."""
    _, log = gravcal.simulate(CONFIG, seed, plan=plan, **ZERO_TRUTH)
    t, v0 = np.asarray(log.t), np.asarray(log.accel)
    b, u = truth
    v = np.linalg.solve(u, M0 * v0.T).T + b
    return t, v


def calibrate(truth, seed):
    t, v = recording(truth, seed)
    return gravcal.calibrate(t=t, accel=v, config=CONFIG)


def named(result, name):
    """The changed term named, or one the data cannot tell apart from it."""
    changed = result.get("changed") or {}
    return changed.get("name") == name or name in (changed.get("indistinguishable") or [])


def difference_sigma(truth, name):
    r = gravcal.compare(calibrate(truth, 900001), calibrate(truth, 900002))
    return next(p["std"] for p in r["parameters"] if p["name"] == "accel." + name)


def pairs(truth, name, k, n, first_seed):
    delta = k * difference_sigma(truth, name)
    other = moved(truth, name, delta)
    alarms = hits = 0
    for i in range(n):
        r = gravcal.compare(calibrate(truth, first_seed + 2 * i),
                            calibrate(other, first_seed + 2 * i + 1))
        if not r["consistent"]:
            alarms += 1
            hits += named(r, "accel." + name)
    print("compare %-6s k=%-2g: changed in %d of %d pairs, named %d" % (name, k, alarms, n, hits),
          flush=True)
    return alarms, hits


def check_plan(hold):
    """plan --verify's four poses (a tetrahedron: every axis sees gravity),
    each held `hold` seconds, as a plan file for the simulator."""
    import json
    import tempfile
    c = 1.0 / np.sqrt(3.0)
    ups = [[c, c, c], [c, -c, -c], [-c, c, -c], [-c, -c, c]]
    path = os.path.join(tempfile.gettempdir(), "heldout_check_plan_%d.json" % os.getpid())
    with open(path, "w") as f:
        json.dump({"poses": [{"up": u, "hold_s": hold} for u in ups]}, f)
    return path


def check_session(truth, seed, hold):
    return recording(truth, seed, plan=check_plan(hold))


def checks(truth, name, k, n, first_seed, hold, at_mdc=False):
    """Four-pose (tetrahedral) check sessions of the truth moved by k stored
    sigmas, or by k times the minimal detectable change the report of that
    session's check claims (its stored calibration's covariance varies with
    the pose scatter each calibration estimated), each against its own
    stored calibration of the truth."""
    alarms = hits = 0
    for i in range(n):
        stored = calibrate(truth, first_seed + 500000 + i)
        same = gravcal.compare(stored, stored)["parameters"]
        index = [p["name"] for p in same].index("accel." + name)
        delta = k * same[index]["std"] / np.sqrt(2.0)
        if at_mdc:
            # The report of a check of the unchanged unit: its claim.
            t, v = check_session(truth, first_seed + 700000 + i, hold)
            probe = gravcal.verify(stored, t=t, accel=v, config=CONFIG)
            delta = k * probe["parameters"][index]["minimal_detectable_change"]
        t, v = check_session(moved(truth, name, delta), first_seed + i, hold)
        r = gravcal.verify(stored, t=t, accel=v, config=CONFIG)
        if not r["consistent"]:
            alarms += 1
            hits += named(r, "accel." + name)
    print("verify  %-6s %s %-4g: changed in %d of %d sessions, named %d"
          % (name, "mdc x" if at_mdc else "k =", k, alarms, n, hits), flush=True)
    return alarms, hits


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 200
    truth = base_truth()
    pairs(truth, "bias_z", 0, n, 1000)
    for name in ("bias_z", "u_xy", "u_yy"):
        pairs(truth, name, 3, n // 4, 3000)
        pairs(truth, name, 5, n // 4, 5000)
        pairs(truth, name, 10, n // 8, 7000)
    hold = 40  # s: four poses of four calibration holds each
    checks(truth, "bias_z", 0, n, 20000, hold)
    for name in ("bias_z", "u_yy", "u_xy"):
        checks(truth, name, 10, n // 4, 30000, hold)
    for name in ("bias_y", "u_zz"):
        checks(truth, name, 1, n, 40000, hold, at_mdc=True)


if __name__ == "__main__":
    main()
