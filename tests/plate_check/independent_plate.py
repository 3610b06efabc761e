#!/usr/bin/python3
"""An independent plate simulator and the held-out check of issue 38.

It shares no code with gravcal's plate simulator (src/simulation/plate_*):
the truth, the motion and the sensors are written here from the documented
conventions only (docs/workflows/multi_imu.md, docs/data_contract.md):

  accelerometer (raw counts):  v = K_a T_a f_h + b_a + noise, rounded
  gyroscope (raw counts):      u = K_g T_g w_h + b_g + noise, rounded
  f_h, w_h: specific force and rate in the unit's housing frame
  housing i from plate:        M_i^T (M_i the mounting, plate from housing)

gravcal reports each unit in its own orthogonalised accelerometer frame,
m = U (v - b) with U upper triangular (positive diagonal), so with
A = (K_a T_a)^-1 = Q U (QR) the truth is U, b_a, M_g = Q^T (K_g T_g)^-1,
b_g, and the rotation into the reference's frame C_i = Q_0^T M_0^T M_i Q_i.
A unit's stamps are late by tau_i: its sample of physical time s carries
the stamp s + tau_i.

The motion: a plate on a table held still in random attitudes (spread over
the sphere), joined by turns along the geodesic with a quintic smooth step;
the Earth's rate at 48 degrees north; each unit a few cm from the turn's
centre (the lever arm gives a small acceleration in the turns).

Usage:
  independent_plate.py generate --imus 3 --seed 1 --out DIR [--layout table|logs]
  independent_plate.py check --gravcal BUILD/gravcal --config configs/multi_imu.yaml
                             --imus 2,3,8 --seeds 10 [--layout table|logs] [--quick]
check prints the rms z per plate size and exits 1 when a Must-show fails.
"""

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

import numpy as np

G = 9.80665
COUNTS_PER_G = 16384.0
COUNTS_PER_DPS = 131.0
EARTH_RATE = 7.292115e-5
LATITUDE = math.radians(48.0)


def hat(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def expm_so3(v):
    a = np.linalg.norm(v)
    if a < 1e-12:
        return np.eye(3) + hat(v)
    k = hat(v / a)
    return np.eye(3) + math.sin(a) * k + (1.0 - math.cos(a)) * (k @ k)


def logm_so3(r):
    c = max(-1.0, min(1.0, (np.trace(r) - 1.0) / 2.0))
    a = math.acos(c)
    if a < 1e-9:
        return np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]) / 2.0
    if a > math.pi - 1e-6:
        # Near a half turn: the axis from the symmetric part.
        s = (r + np.eye(3)) / 2.0
        j = int(np.argmax(np.diag(s)))
        axis = s[:, j] / math.sqrt(s[j, j])
        return axis * a
    w = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    return w * a / (2.0 * math.sin(a))


def random_rotation(rng):
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def small_rotation(rng, max_deg):
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    return expm_so3(axis * math.radians(rng.uniform(0.0, max_deg)))


def qr_positive(a):
    q, u = np.linalg.qr(a)
    s = np.diag(np.sign(np.diag(u)))
    return q @ s, s @ u


# A permuted and flipped mounting: x and y swapped, z reversed (a half turn
# about (1, 1, 0)/sqrt(2); det +1).
PERMUTED = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])


def make_truth(rng, n_imus, permuted, mounting):
    units = []
    for i in range(n_imus):
        if mounting == "random":
            m = random_rotation(rng)
        else:
            m = small_rotation(rng, 3.0)
        if i == permuted:
            # The unit's axes read permuted: its housing turned by PERMUTED.
            m = m @ PERMUTED
        # Accelerometer: scale 2 %, axis misalignment 0.5 deg, bias 40 mg.
        ka = np.diag(COUNTS_PER_G / G * (1.0 + rng.normal(0.0, 0.02, 3)))
        ta = np.eye(3) + rng.normal(0.0, math.radians(0.5), (3, 3)) * (1 - np.eye(3))
        ba = rng.normal(0.0, 0.04 * COUNTS_PER_G, 3)
        kg = np.diag(COUNTS_PER_DPS * 180.0 / math.pi * (1.0 + rng.normal(0.0, 0.02, 3)))
        tg = np.eye(3) + rng.normal(0.0, math.radians(0.5), (3, 3)) * (1 - np.eye(3))
        # The gyroscope triad turned against the accelerometer's by ~0.5 deg.
        tg = tg @ small_rotation(rng, 0.7)
        bg = rng.normal(0.0, 1.0 * COUNTS_PER_DPS, 3)
        lever = rng.uniform(-0.06, 0.06, 3)
        units.append(dict(mounting=m, ka=ka, ta=ta, ba=ba, kg=kg, tg=tg, bg=bg, lever=lever))
    for u in units:
        q, upper = qr_positive(np.linalg.inv(u["ka"] @ u["ta"]))
        u["q"] = q
        u["upper"] = upper
        u["gyro_matrix"] = q.T @ np.linalg.inv(u["kg"] @ u["tg"])
    q0, m0 = units[0]["q"], units[0]["mounting"]
    for u in units:
        u["rotation"] = q0.T @ m0.T @ u["mounting"] @ u["q"]
    return units


def make_attitudes(rng, count):
    """Random plate attitudes (world from plate) whose gravity directions
    span the sphere, each turn between 45 and 170 degrees."""
    while True:
        atts = [random_rotation(rng)]
        while len(atts) < count:
            r = random_rotation(rng)
            angle = np.linalg.norm(logm_so3(atts[-1].T @ r))
            if math.radians(45) < angle < math.radians(170):
                atts.append(r)
        ups = np.array([a.T @ np.array([0.0, 0.0, 1.0]) for a in atts])
        if np.linalg.eigvalsh(ups.T @ ups / count).min() > 0.15:
            return atts


def motion(atts, hold, turn, t_phys):
    """Plate attitude W (world from plate), body rate, body angular
    acceleration at physical times t_phys (array)."""
    n = len(atts)
    period = hold + turn
    phis = [logm_so3(atts[k].T @ atts[k + 1]) for k in range(n - 1)]
    w_out = np.zeros((len(t_phys), 3, 3))
    rate = np.zeros((len(t_phys), 3))
    acc = np.zeros((len(t_phys), 3))
    for j, t in enumerate(t_phys):
        k = int(min(max(t, 0.0) // period, n - 1))
        x = t - k * period - hold
        if k >= n - 1 or x <= 0.0:
            w_out[j] = atts[min(k, n - 1)]
            continue
        x /= turn
        s = 10 * x**3 - 15 * x**4 + 6 * x**5
        ds = (30 * x**2 - 60 * x**3 + 30 * x**4) / turn
        dds = (60 * x - 180 * x**2 + 120 * x**3) / turn**2
        w_out[j] = atts[k] @ expm_so3(s * phis[k])
        rate[j] = ds * phis[k]
        acc[j] = dds * phis[k]
    return w_out, rate, acc


def sense(unit, atts, hold, turn, stamps, tau, rng, noise):
    """One unit's raw samples at its stamps (stamps late by tau)."""
    t_phys = stamps - tau
    w, rate, alpha = motion(atts, hold, turn, t_phys)
    earth = EARTH_RATE * np.array([0.0, math.cos(LATITUDE), math.sin(LATITUDE)])
    up = np.array([0.0, 0.0, G])
    r = unit["lever"]
    f_plate = np.einsum("nji,j->ni", w, up)  # W^T (0, 0, g)
    f_plate += np.cross(alpha, r) + np.cross(rate, np.cross(rate, r))
    w_plate = rate + np.einsum("nji,j->ni", w, earth)
    mt = unit["mounting"].T
    f_h = f_plate @ mt.T
    w_h = w_plate @ mt.T
    a_counts = f_h @ (unit["ka"] @ unit["ta"]).T + unit["ba"]
    g_counts = w_h @ (unit["kg"] @ unit["tg"]).T + unit["bg"]
    # White noise: 120 ug/sqrt(Hz) and 0.007 deg/s/sqrt(Hz).
    fs = 1.0 / np.median(np.diff(stamps))
    a_counts += rng.normal(0.0, noise * 120e-6 * COUNTS_PER_G * math.sqrt(fs), a_counts.shape)
    g_counts += rng.normal(0.0, noise * 0.007 * COUNTS_PER_DPS * math.sqrt(fs), g_counts.shape)
    return np.round(a_counts), np.round(g_counts)


def generate(n_imus, seed, out, layout="table", mounting="small", rate=100.0, poses=14,
             hold=4.0, turn=2.0, noise=1.0):
    rng = np.random.default_rng(seed)
    permuted = n_imus - 1 if n_imus >= 2 else -1
    units = make_truth(rng, n_imus, permuted, mounting)
    atts = make_attitudes(rng, poses)
    taus = [0.0] + list(rng.uniform(0.0, 0.030, n_imus - 1))
    duration = poses * (hold + turn) - turn + 1.0
    os.makedirs(out, exist_ok=True)
    t0 = 37.25
    names = ["imu%d" % i for i in range(n_imus)]
    if layout == "table":
        stamps = t0 + np.arange(0.0, duration, 1.0 / rate)
        cols = [stamps[:, None]]
        header = ["t"]
        for i, u in enumerate(units):
            a, g = sense(u, atts, hold, turn, stamps - t0, taus[i], rng, noise)
            cols += [a, g]
            header += ["%s.%s" % (names[i], c) for c in ("ax", "ay", "az", "gx", "gy", "gz")]
        table = np.hstack(cols)
        with open(os.path.join(out, "plate.csv"), "w") as f:
            f.write(",".join(header) + "\n")
            for row in table:
                f.write("%.6f," % row[0] + ",".join("%d" % x for x in row[1:]) + "\n")
    elif layout == "bag":
        # A rosbag2 (SQLite, CDR) with one sensor_msgs/msg/Imu topic per
        # unit, each at its own rate and phase, in SI (the nominal scales).
        sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                                        "formats"))
        from write_formats import cdr_imu
        import sqlite3
        db = sqlite3.connect(os.path.join(out, "plate.db3"))
        db.executescript("""
            CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);
            INSERT INTO schema VALUES (3, 'humble');
            CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,
                                serialization_format TEXT NOT NULL,
                                offered_qos_profiles TEXT NOT NULL);
            CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL,
                                  timestamp INTEGER NOT NULL, data BLOB NOT NULL);
        """)
        rows = []
        for i, u in enumerate(units):
            db.execute("INSERT INTO topics VALUES (?, ?, ?, ?, ?)",
                       (i + 1, "/%s/data" % names[i], "sensor_msgs/msg/Imu", "cdr", ""))
            fs = rate * (1.0 if i % 2 == 0 else 2.0)
            phase = rng.uniform(0.0, 1.0 / fs)
            stamps = phase + np.arange(0.0, duration, 1.0 / fs)
            a, g = sense(u, atts, hold, turn, stamps, taus[i], rng, noise)
            a *= G / COUNTS_PER_G
            g *= math.pi / 180.0 / COUNTS_PER_DPS
            for k in range(len(stamps)):
                ns = int(round((t0 + stamps[k]) * 1e9))
                rows.append((i + 1, ns + 2000000, cdr_imu(ns, list(a[k]), list(g[k]))))
        rows.sort(key=lambda r: r[1])
        db.executemany("INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)", rows)
        db.commit()
        db.close()
    else:
        # One log per unit, each at its own rate and phase, one clock.
        for i, u in enumerate(units):
            fs = rate * (1.0 if i % 2 == 0 else 2.0)
            phase = rng.uniform(0.0, 1.0 / fs)
            stamps = phase + np.arange(0.0, duration, 1.0 / fs)
            a, g = sense(u, atts, hold, turn, stamps, taus[i], rng, noise)
            with open(os.path.join(out, names[i] + ".csv"), "w") as f:
                f.write("t,ax,ay,az,gx,gy,gz\n")
                for k in range(len(stamps)):
                    f.write("%.6f," % (t0 + stamps[k]) +
                            ",".join("%d" % x for x in np.concatenate([a[k], g[k]])) + "\n")
    truth = {"imus": []}
    # The bag holds SI (raw counts times the nominal scales sa, sg): there
    # b_SI = sa b, U_SI = U / sa, and the same for the gyroscope.
    sa = G / COUNTS_PER_G if layout == "bag" else 1.0
    sg = math.pi / 180.0 / COUNTS_PER_DPS if layout == "bag" else 1.0
    for i, u in enumerate(units):
        truth["imus"].append({
            "name": names[i],
            "accel_bias": (u["ba"] * sa).tolist(),
            "upper": (u["upper"] / sa).tolist(),
            "gyro_bias": (u["bg"] * sg).tolist(),
            "gyro_matrix": (u["gyro_matrix"] / sg).tolist(),
            "rotation": u["rotation"].tolist(),
            "time_offset": taus[i] - taus[0],
            "permuted": i == permuted,
        })
        if mounting == "random":
            stated = units[i]["mounting"]
            if i == permuted:
                stated = stated @ PERMUTED.T
            truth["imus"][-1]["stated_mounting"] = stated.tolist()
    with open(os.path.join(out, "truth.json"), "w") as f:
        json.dump(truth, f, indent=1)
    return truth


def listed_config(shipped, out, truth, layout):
    """The shipped config with `imus:` listing the units: one log per unit
    (layout logs) and each unit's stated mounting (plate from housing) where
    the truth states one (random mountings; the permuted unit's stated
    mounting leaves its permutation out)."""
    lines = []
    for line in open(shipped):
        if not line.startswith("imus:"):
            lines.append(line)
            continue
        lines.append("imus:\n")
        for t in truth["imus"]:
            lines.append("  - name: %s\n" % t["name"])
            if layout == "logs":
                lines.append("    input: %s\n" % os.path.join(out, t["name"] + ".csv"))
            if layout == "bag":
                lines.append("    topic: /%s/data\n    accel_units: m/s^2\n"
                             "    gyro_units: rad/s\n" % t["name"])
            if "stated_mounting" in t:
                lines.append("    rotation: %s\n" % json.dumps(t["stated_mounting"]))
    path = os.path.join(out, "config.yaml")
    with open(path, "w") as f:
        f.writelines(lines)
    return path


def calibrate(gravcal, config, out, layout, truth):
    cal = os.path.join(out, "cal")
    args = [gravcal, "calibrate", "--output-dir", cal]
    if layout != "table" or "stated_mounting" in truth["imus"][0]:
        config = listed_config(config, out, truth, layout)
    args += ["--config", config]
    if layout == "table":
        args += ["--input", os.path.join(out, "plate.csv")]
    elif layout == "bag":
        args += ["--input", os.path.join(out, "plate.db3")]
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError("calibrate failed: " + r.stderr.strip())
    return cal, r.stderr


def evaluate(truth, cal, stderr):
    """z values of intrinsics and rotations, of time offsets, the sigma
    ratios joint / separate, and whether the permuted unit was named."""
    assembly = json.load(open(os.path.join(cal, "assembly.json")))
    z_intr, z_rot, z_tau, ratios = [], [], [], []
    named = None
    warnings = " ".join(assembly.get("warnings", [])) + stderr
    for k, t in enumerate(truth["imus"]):
        c = json.load(open(os.path.join(cal, t["name"] + ".json")))
        a = assembly["imus"][k]
        assert a["name"] == t["name"]
        # Accelerometer: bias_x..z, u_xx u_xy u_xz u_yy u_yz u_zz.
        up_t, up_e = np.array(t["upper"]), np.array(c["accel"]["upper"])
        err = np.concatenate([np.array(c["accel"]["bias"]) - t["accel_bias"],
                              [up_e[r, s] - up_t[r, s] for r, s in
                               ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))]])
        cov = np.array(c["accel"]["covariance"]["matrix"])
        z_intr += list(err / np.sqrt(np.diag(cov)))
        gerr = np.concatenate([np.array(c["gyro"]["bias"]) - t["gyro_bias"],
                               (np.array(c["gyro"]["matrix"]) - t["gyro_matrix"]).ravel()])
        gcov = np.array(c["gyro"]["covariance"]["matrix"])
        z_intr += list(gerr / np.sqrt(np.diag(gcov)))
        if k > 0:
            r_e, r_t = np.array(a["rotation"]), np.array(t["rotation"])
            e = logm_so3(r_e.T @ r_t)
            z_rot += list(e / np.array(a["rotation_sigma"]))
            if a["time_offset"] is not None:
                z_tau.append((a["time_offset"] - t["time_offset"]) / a["time_offset_sigma"])
        js = a.get("joint_vs_separate")
        if js:
            for j, s in zip(js["joint_sigma"], js["separate_sigma"]):
                if j is not None and s is not None and s > 0:
                    ratios.append(j / s)
        if t["permuted"]:
            named = (t["name"] + " looks rotated") in warnings
    return z_intr, z_rot, z_tau, ratios, named


def rms(x):
    return float(np.sqrt(np.mean(np.square(x)))) if len(x) else float("nan")


def allowed_beyond(n, p, alpha):
    """The smallest k with P(X > k) < alpha, X ~ Binomial(n, p)."""
    tail = 1.0
    for k in range(n + 1):
        tail -= math.comb(n, k) * p**k * (1.0 - p)**(n - k)
        if tail < alpha:
            return k
    return n


def check_layout(args, layout):
    ok = True
    report = {}
    sizes = [int(x) for x in args.imus.split(",")]
    # --pooled: the Must-show over the values of every plate size at once
    # (a cheap run of a few plates).
    groups = [sizes] if args.pooled else [[n] for n in sizes]
    for group in groups:
        zi, zr, zt, ratios, named = [], [], [], [], []
        for n, seed in [(n, seed) for n in group
                        for seed in range(args.first_seed, args.first_seed + args.seeds)]:
            with tempfile.TemporaryDirectory() as tmp:
                truth = generate(n, seed, tmp, layout=layout, mounting=args.mounting,
                                 hold=args.hold, turn=args.turn, poses=args.poses,
                                 noise=args.noise)
                cal, err = calibrate(args.gravcal, args.config, tmp, layout, truth)
                a, b, c, d, e = evaluate(truth, cal, err)
                zi += a
                zr += b
                zt += c
                ratios += d
                named.append(e)
        within = float(np.mean(np.abs(zt) <= 2.0)) if zt else float("nan")
        n = ",".join(str(x) for x in group)
        row = {"imus": n, "layout": layout, "seeds": args.seeds, "rms_z_intrinsics": rms(zi),
               "rms_z_rotations": rms(zr), "rms_z_time_offsets": rms(zt),
               "time_offsets_within_2_sigma": within, "max_joint_over_separate":
               max(ratios) if ratios else float("nan"),
               "median_joint_over_separate": float(np.median(ratios)) if ratios else float("nan"),
               "permuted_named": sum(1 for x in named if x), "plates": len(named)}
        report[n] = row
        print(json.dumps(row))
        sys.stdout.flush()
        bad = []
        if not 0.7 <= row["rms_z_intrinsics"] <= 1.4:
            bad.append("rms z of the intrinsics")
        if not 0.7 <= row["rms_z_rotations"] <= 1.4:
            bad.append("rms z of the rotations")
        # Within 2 sigma: each offset is beyond with probability 0.0455, so
        # a few are by chance; more than the binomial's 99 % quantile fail.
        beyond = int(np.sum(np.abs(zt) > 2.0))
        if beyond > allowed_beyond(len(zt), 0.0455, 0.01):
            bad.append("time offsets within 2 sigma (%d of %d beyond)" % (beyond, len(zt)))
        if row["permuted_named"] != row["plates"]:
            bad.append("the permuted unit named")
        if ratios and row["max_joint_over_separate"] > 1.0 + 1e-6:
            bad.append("joint sigmas no larger than separate")
        if bad:
            ok = False
            print("FAIL %s IMUs, %s: %s" % (n, layout, ", ".join(bad)))
    return ok


def check(args):
    ok = True
    for layout in args.layout.split(","):
        imus = args.imus
        if ":" in args.layout_imus:
            # layout:imus;layout:imus (e.g. table:2,3;bag:2).
            for part in args.layout_imus.split(";"):
                name, _, sizes = part.partition(":")
                if name == layout:
                    imus = sizes
        ok = check_layout(argparse.Namespace(**{**vars(args), "imus": imus}), layout) and ok
    return 0 if ok else 1


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = p.add_subparsers(dest="command", required=True)
    g = sub.add_parser("generate")
    g.add_argument("--imus", type=int, default=3)
    g.add_argument("--seed", type=int, default=1)
    g.add_argument("--out", required=True)
    g.add_argument("--layout", choices=["table", "logs", "bag"], default="table")
    g.add_argument("--mounting", choices=["small", "random"], default="small")
    c = sub.add_parser("check")
    c.add_argument("--gravcal", required=True)
    c.add_argument("--config", required=True)
    c.add_argument("--imus", default="2,3,8")
    c.add_argument("--seeds", type=int, default=10)
    c.add_argument("--first-seed", type=int, default=1000)
    c.add_argument("--layout", default="table",
                   help="table, logs, bag or a comma list of them")
    c.add_argument("--layout-imus", default="",
                   help="plate sizes per layout: table:2,3;bag:2 (else --imus)")
    c.add_argument("--mounting", choices=["small", "random"], default="small")
    c.add_argument("--poses", type=int, default=14)
    c.add_argument("--hold", type=float, default=4.0)
    c.add_argument("--turn", type=float, default=2.0)
    c.add_argument("--noise", type=float, default=1.0, help="white noise times this")
    c.add_argument("--pooled", action="store_true",
                   help="check the values of every plate size together")
    args = p.parse_args()
    if args.command == "generate":
        generate(args.imus, args.seed, args.out, layout=args.layout, mounting=args.mounting)
        return 0
    return check(args)


if __name__ == "__main__":
    sys.exit(main())
