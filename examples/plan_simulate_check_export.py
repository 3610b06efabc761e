#!/usr/bin/env python3
"""Plan a recording, simulate a session that follows the plan, check what
it determines, calibrate it and export the calibration as C source: the
`gravcal plan`, `simulate --plan`, `check`, `calibrate` and `export` chain
from Python.

    PYTHONPATH=build/python python3 examples/plan_simulate_check_export.py [--out folder]
"""
import argparse
import os
import tempfile

import gravcal

HERE = os.path.dirname(os.path.abspath(__file__))
CONFIG = os.path.join(HERE, "..", "configs", "twelve_position.yaml")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", help="folder for plan.json and the C files (default: a "
                        "temporary one)")
    parser.add_argument("--seed", type=int, default=3)
    args = parser.parse_args()
    out = args.out or tempfile.mkdtemp(prefix="gravcal_")
    os.makedirs(out, exist_ok=True)

    cfg = gravcal.config(CONFIG)
    # A datasheet's white noise (m/s^2/sqrt(Hz)) in place of a noise.json.
    plan_path = os.path.join(out, "plan.json")
    plan = gravcal.plan(cfg, target="accel_bias=0.5mg accel_scale=100ppm",
                        accel_noise_density=0.002, output=plan_path)
    print("plan:", plan["message"])
    for pose in plan["poses"][:3]:
        print("  hold %.1f s: %s" % (pose["hold_s"], pose["instruction"]))

    truth, log = gravcal.simulate(cfg, args.seed, plan=plan_path)
    report = gravcal.check(log, config=cfg, target="accel_bias=0.5mg accel_scale=100ppm")
    print(report["text"], end="")

    cal = gravcal.calibrate(log, config=cfg)
    print("accel bias estimate", cal.accel.bias, "truth", truth["accel"]["bias"])
    exported = gravcal.export(cal, "c", name="simulated session")
    for f in exported["files"]:
        with open(os.path.join(out, f["name"]), "w") as stream:
            stream.write(f["text"])
    print("%s; wrote %s in %s" % (exported["message"],
                                  ", ".join(f["name"] for f in exported["files"]), out))


if __name__ == "__main__":
    main()
