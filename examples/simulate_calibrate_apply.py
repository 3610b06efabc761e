#!/usr/bin/env python3
"""Simulate a twelve-position session, calibrate it, apply the calibration,
and compare with the simulator's truth; plots |a| before and after when
matplotlib is installed.

    PYTHONPATH=build/python python3 examples/simulate_calibrate_apply.py [--plot out.png]
"""
import argparse
import os

import numpy as np

import gravcal

HERE = os.path.dirname(os.path.abspath(__file__))
CONFIG = os.path.join(HERE, "..", "configs", "twelve_position_gyro.yaml")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--plot", help="save the figure here instead of showing it")
    args = parser.parse_args()

    truth, log = gravcal.simulate(config=CONFIG, seed=args.seed)
    print("simulated %d samples (%s), seed %d" % (len(log), log.source, args.seed))

    cal = gravcal.calibrate(log, config=CONFIG)
    for w in cal.warnings:
        print("warning:", w)
    true_bias = np.asarray(truth["accel"]["bias"])
    print("accel bias  truth    ", np.array2string(true_bias, precision=2))
    print("            estimate ", np.array2string(cal.accel.bias, precision=2))
    print("            std      ", np.array2string(cal.accel.std.bias, precision=2))
    print("            err/std  ", np.array2string((cal.accel.bias - true_bias) /
                                                   cal.accel.std.bias, precision=2))

    accel, gyro = cal.apply(log.accel, log.gyro, temp=log.temp, t=log.t)
    g = truth["gravity"]
    norm = np.linalg.norm(accel, axis=1)
    still = np.abs(np.linalg.norm(gyro, axis=1)) < 0.05
    print("|a| - g while still: rms %.4f m/s^2 over %d samples" %
          (np.sqrt(np.mean((norm[still] - g) ** 2)), still.sum()))

    try:
        import matplotlib
        if args.plot:
            matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no plot")
        return
    nominal = np.linalg.norm(log.accel, axis=1) * g / np.median(
        np.linalg.norm(log.accel[still], axis=1))
    fig, ax = plt.subplots(figsize=(9, 4))
    ax.plot(log.t, nominal - g, lw=0.5, label="raw, nominal scale")
    ax.plot(log.t, norm - g, lw=0.5, label="calibrated")
    ax.set_ylim(-0.5, 0.5)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("|a| - g [m/s^2]")
    ax.legend()
    fig.tight_layout()
    if args.plot:
        fig.savefig(args.plot, dpi=100)
        print("wrote", args.plot)
    else:
        plt.show()


if __name__ == "__main__":
    main()
