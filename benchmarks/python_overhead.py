"""Overhead of gravcal.calibrate from Python over the C++ call (issue 18).

Times, in one process and interleaved, on the same twelve-position session
in memory (configs/twelve_position.yaml, simulated seed 1):
  C++:    RunCalibration on a prepared PipelineInput, called in a C++ loop
          (gravcal._gravcal._time_calibrate);
  Python: gravcal.calibrate(log, config=cfg) with a prepared Config, the
          whole Python call (argument checks, the log handed to C++, the
          calibration JSON built and wrapped in a Calibration).
Prints the medians of the rounds and the ratio. Run with the build's
module on PYTHONPATH:
  PYTHONPATH=build/python python3 benchmarks/python_overhead.py
"""
import os
import statistics
import sys
import time

import gravcal
from gravcal import _gravcal

ROUNDS = int(os.environ.get("ROUNDS", "15"))
CALLS = int(os.environ.get("CALLS", "20"))


def main():
    source = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    cfg = gravcal.config(os.path.join(source, "configs", "twelve_position.yaml"))
    _, log = gravcal.simulate(cfg, seed=1)
    gravcal.calibrate(log, config=cfg)  # warm up
    cpp, py = [], []
    for _ in range(ROUNDS):
        cpp.append(_gravcal._time_calibrate(cfg, log, CALLS))
        start = time.perf_counter()
        for _ in range(CALLS):
            gravcal.calibrate(log, config=cfg)
        py.append((time.perf_counter() - start) / CALLS)
    c, p = statistics.median(cpp), statistics.median(py)
    print("session: %d samples, %s" % (len(log), cfg.method))
    print("C++ RunCalibration:         %8.1f us per call (median of %d rounds x %d calls)"
          % (c * 1e6, ROUNDS, CALLS))
    print("Python gravcal.calibrate:   %8.1f us per call" % (p * 1e6))
    print("ratio Python / C++:         %8.4f (overhead %.2f %%)" % (p / c, 100 * (p / c - 1)))
    return 0 if p / c < 1.05 else 1


if __name__ == "__main__":
    sys.exit(main())
