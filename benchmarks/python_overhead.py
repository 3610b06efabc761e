"""Overhead of gravcal.calibrate from Python over the C++ call (issue 18).

Times, in one process and interleaved, on the same twelve-position session
(configs/twelve_position.yaml, simulated seed 1, 16,300 samples), two cases:
  log in memory: C++ RunCalibration on the log (a PipelineInput), in a C++
          loop (gravcal._gravcal._time_calibrate), against
          gravcal.calibrate(log, config=cfg);
  CSV file: C++ ReadImuLog + RunCalibration (what `gravcal calibrate`
          does), against gravcal.calibrate("session.csv", config=cfg).
Both sides measure the CPU time of the calling thread (the library runs
single-threaded here), so other processes loading the machine inflate
neither. The Python figure is the whole call: argument handling, the config check,
the call, and the Calibration object around the result; the row
"(extension)" calls the C++ extension's function directly, without the
pure-Python layer.
Prints the medians of the rounds and the ratio. Run with the build's
module on PYTHONPATH:
  PYTHONPATH=build/python python3 benchmarks/python_overhead.py
"""
import os
import statistics
import sys
import tempfile
import time

import gravcal
from gravcal import _gravcal

ROUNDS = int(os.environ.get("ROUNDS", "30"))
CALLS = int(os.environ.get("CALLS", "50"))


def measure(cpp_call, py_call):
    """Medians over ROUNDS of the mean of CALLS calls, C++ and Python rounds
    interleaved (C++ first in even rounds, Python first in odd ones) so that
    a change of machine load hits both."""

    def python_round():
        start = time.thread_time()
        for _ in range(CALLS):
            py_call()
        return (time.thread_time() - start) / CALLS

    py_call()  # warm up
    cpp, py = [], []
    for r in range(ROUNDS):
        if r % 2:
            py.append(python_round())
            cpp.append(cpp_call())
        else:
            cpp.append(cpp_call())
            py.append(python_round())
    return statistics.median(cpp), statistics.median(py)


def main():
    source = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    cfg = gravcal.config(os.path.join(source, "configs", "twelve_position.yaml"))
    _, log = gravcal.simulate(cfg, seed=1)
    path = os.path.join(tempfile.mkdtemp(), "session.csv")
    log.to_csv(path)
    print("session: %d samples, %s, %d rounds x %d calls" % (len(log), cfg.method, ROUNDS, CALLS))
    worst = 0.0  # over the two user-facing cases
    cases = [
        ("log in memory", lambda: _gravcal._time_calibrate(cfg, log, "", CALLS),
         lambda: gravcal.calibrate(log, config=cfg)),
        ("  (extension)", lambda: _gravcal._time_calibrate(cfg, log, "", CALLS),
         lambda: _gravcal.calibrate(cfg, log, "", "", "")),
        ("CSV file", lambda: _gravcal._time_calibrate(cfg, log, path, CALLS),
         lambda: gravcal.calibrate(path, config=cfg)),
    ]
    for name, cpp_call, py_call in cases:
        c, p = measure(cpp_call, py_call)
        if not name.startswith(" "):
            worst = max(worst, p / c)
        print("%-14s C++ %8.1f us, Python %8.1f us per call: ratio %.4f (overhead %+.2f %%)"
              % (name, c * 1e6, p * 1e6, p / c, 100 * (p / c - 1)))
    os.remove(path)
    return 0 if worst < 1.05 else 1


if __name__ == "__main__":
    sys.exit(main())
