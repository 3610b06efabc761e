"""Overhead of gravcal.calibrate from Python over the C++ call (issue 18).

Times, in one process, on the same twelve-position session
(configs/twelve_position.yaml, simulated seed 1, 16,300 samples), two cases:
  log in memory: C++ RunCalibration on the log (a PipelineInput), timed
          inside the extension (gravcal._gravcal._time_calibrate), against
          gravcal.calibrate(log, config=cfg);
  CSV file: C++ ReadImuLog + RunCalibration (what `gravcal calibrate`
          does), against gravcal.calibrate("session.csv", config=cfg).
Both sides measure the CPU time of the calling thread (the library runs
single-threaded here), so other processes do not add their own time to
either. The Python figure is the whole call: argument handling, the call,
and the Calibration object around the result (and its destruction).

The calls alternate one by one (C++, Python, Python, C++, ...), so that a
change of machine load, of CPU frequency or of what the other core runs
hits both sides alike; the ratio is the median of the Python calls over the
median of the C++ calls of the same run (and, as a check, the median of the
ratios of neighbouring pairs). Run with the build's module on PYTHONPATH:
  PYTHONPATH=build/python python3 benchmarks/python_overhead.py
Exits 1 when a user-facing ratio is 1.05 or more.
"""
import os
import statistics
import sys
import tempfile
import time

import gravcal
from gravcal import _gravcal

PAIRS = int(os.environ.get("PAIRS", "1500"))


def measure(cpp_call, py_call):
    """(C++ median, Python median, median of pair ratios) in seconds over
    PAIRS alternating pairs, after a warm-up."""
    clock = time.thread_time

    def python_once():
        start = clock()
        py_call()
        return clock() - start

    for _ in range(20):
        cpp_call()
        py_call()
    cpp, py = [], []
    for r in range(PAIRS):
        if r % 2:
            p = python_once()
            c = cpp_call()
        else:
            c = cpp_call()
            p = python_once()
        cpp.append(c)
        py.append(p)
    ratios = [p / c for p, c in zip(py, cpp)]
    return statistics.median(cpp), statistics.median(py), statistics.median(ratios)


def main():
    source = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    cfg = gravcal.config(os.path.join(source, "configs", "twelve_position.yaml"))
    _, log = gravcal.simulate(cfg, seed=1)
    path = os.path.join(tempfile.mkdtemp(), "session.csv")
    log.to_csv(path)
    print("session: %d samples, %s, %d alternating pairs of calls, Python %s"
          % (len(log), cfg.method, PAIRS, sys.version.split()[0]))
    worst = 0.0
    cases = [
        ("log in memory", lambda: _gravcal._time_calibrate(cfg, log, "", 1),
         lambda: gravcal.calibrate(log, config=cfg)),
        ("CSV file", lambda: _gravcal._time_calibrate(cfg, log, path, 1),
         lambda: gravcal.calibrate(path, config=cfg)),
    ]
    for name, cpp_call, py_call in cases:
        c, p, pair = measure(cpp_call, py_call)
        worst = max(worst, p / c, pair)
        print("%-14s C++ %8.1f us, Python %8.1f us per call: ratio %.4f "
              "(median pair ratio %.4f, overhead %+.2f %%)"
              % (name, c * 1e6, p * 1e6, p / c, pair, 100 * (p / c - 1)))
    os.remove(path)
    return 0 if worst < 1.05 else 1


if __name__ == "__main__":
    sys.exit(main())
