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

The calls alternate one by one (C++, extension, Python, then Python,
extension, C++, ...), so that a change of machine load, of CPU frequency or
of what the other core runs hits every side alike; a ratio is the median of
one side's calls over the median of the C++ calls of the same run (and, as a
check, the median of the ratios within a round). The extension row calls
the C++ extension's function directly, without the pure-Python layer. Run
with the build's module on PYTHONPATH:
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

ROUNDS = int(os.environ.get("ROUNDS", "1000"))


def measure(calls):
    """Medians in seconds of each of `calls` (functions returning the CPU
    seconds of one call) over ROUNDS rounds, after a warm-up. Within a
    round the calls run one after the other, in reversed order every other
    round; the pair ratio is the median over rounds of last / first."""
    for _ in range(20):
        for call in calls:
            call()
    times = [[] for _ in calls]
    for r in range(ROUNDS):
        order = range(len(calls)) if r % 2 else reversed(range(len(calls)))
        for i in order:
            times[i].append(calls[i]())
    pair = statistics.median(p / c for p, c in zip(times[-1], times[0]))
    return [statistics.median(t) for t in times], pair


def timed(call):
    """`call` as a function returning its thread CPU seconds."""
    clock = time.thread_time

    def run():
        start = clock()
        call()
        return clock() - start

    return run


def main():
    source = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    cfg = gravcal.config(os.path.join(source, "configs", "twelve_position.yaml"))
    _, log = gravcal.simulate(cfg, seed=1)
    path = os.path.join(tempfile.mkdtemp(), "session.csv")
    log.to_csv(path)
    print("session: %d samples, %s, %d rounds, Python %s"
          % (len(log), cfg.method, ROUNDS, sys.version.split()[0]))
    worst = 0.0
    cases = [
        ("log in memory", [lambda: _gravcal._time_calibrate(cfg, log, "", 1),
                           timed(lambda: _gravcal.calibrate(cfg, log, "", "", "")),
                           timed(lambda: gravcal.calibrate(log, config=cfg))]),
        ("CSV file", [lambda: _gravcal._time_calibrate(cfg, log, path, 1),
                      timed(lambda: _gravcal.calibrate_file(cfg, path, "", "", "")),
                      timed(lambda: gravcal.calibrate(path, config=cfg))]),
    ]
    for name, calls in cases:
        (c, e, p), pair = measure(calls)
        worst = max(worst, p / c, pair)
        print("%-13s C++ %7.1f us | extension %7.1f us, ratio %.4f | gravcal.calibrate %7.1f us, "
              "ratio %.4f (median pair ratio %.4f)" % (name, c * 1e6, e * 1e6, e / c, p * 1e6,
                                                       p / c, pair))
    os.remove(path)
    return 0 if worst < 1.05 else 1


if __name__ == "__main__":
    sys.exit(main())
