#!/usr/bin/env python3
"""A production-line test station in the style of OpenHTF: phases that
calibrate a unit, check it against acceptance limits, record every limit as
a measurement and attach the calibration certificate to the test record.

    PYTHONPATH=build/python python3 examples/test_station.py LOG --unit SN-0042 \\
        --limits limits.yaml --config configs/twelve_position.yaml --out station/

Without a LOG (``--simulate SEED``) it simulates the session first. It exits
0 when the unit passes, 1 when a limit fails. Plain Python: the small
``TestRecord`` below plays OpenHTF's role (phases, measurements with limits,
attachments, an outcome). When ``openhtf`` is importable,
``openhtf_test()`` builds the same station as an ``openhtf.Test`` (each
limit's value a measurement, the verdict a measurement that must equal
"pass", the certificate an attachment).
"""
import argparse
import datetime
import json
import os
import sys

import gravcal


class TestRecord:
    """What a phase writes: measurements (name -> value, limits, outcome),
    attachments (name -> bytes) and the overall outcome."""

    def __init__(self, unit):
        self.unit = unit
        self.start = datetime.datetime.now(datetime.timezone.utc).isoformat()
        self.measurements = {}
        self.attachments = {}
        self.phases = []
        self.state = {}

    def measure(self, name, value, low=None, high=None, passed=None, note=""):
        if passed is None:
            passed = value is not None and (low is None or value >= low) and (
                high is None or value <= high)
        self.measurements[name] = {"value": value, "low": low, "high": high,
                                   "outcome": "PASS" if passed else "FAIL", "note": note}

    def attach(self, name, data):
        self.attachments[name] = data if isinstance(data, bytes) else data.encode("utf-8")

    @property
    def outcome(self):
        failed = any(m["outcome"] == "FAIL" for m in self.measurements.values())
        return "FAIL" if failed or "error" in self.state else "PASS"

    def to_json(self):
        return {"unit": self.unit, "start": self.start, "outcome": self.outcome,
                "phases": self.phases, "measurements": self.measurements,
                "attachments": sorted(self.attachments)}


# ---------------------------------------------------------------------------
# Phases: each takes the record and the station's settings.

def calibrate_phase(record, settings):
    """Calibrates the unit's log with the station's config (a calibration
    that fails raises gravcal.Error: the phase errors)."""
    record.state["calibration"] = gravcal.calibrate(settings["log"], config=settings["config"])


def limits_phase(record, settings):
    """Every acceptance limit as one measurement (measured value, its
    min and max, pass or fail; a limit the data cannot check passes with a
    note)."""
    result = gravcal.check_limits(record.state["calibration"], settings["limits"])
    for check in result.limits:
        low = None if check.min is None or check.min == -float("inf") else check.min
        high = None if check.max is None or check.max == float("inf") else check.max
        record.measure(check.name, check.measured, low, high, passed=bool(check["pass"]),
                       note=check.why)
    record.state["verdict"] = result.verdict


def certificate_phase(record, settings):
    """The certificate (JSON and HTML) attached to the record, and the
    calibration itself."""
    cert, html = gravcal.certificate(
        record.state["calibration"], limits=settings["limits"], unit=record.unit,
        station=settings.get("station"), input_file=settings.get("input_file", ""),
        config_file=settings["config"])
    record.attach("certificate.json", json.dumps(cert, indent=2))
    record.attach("certificate.html", html)
    record.attach("calibration.json", record.state["calibration"].to_json())


PHASES = [calibrate_phase, limits_phase, certificate_phase]


def run_station(unit, settings):
    """Runs the phases in order; a phase that raises ends the test (outcome
    FAIL, the error recorded)."""
    record = TestRecord(unit)
    for phase in PHASES:
        try:
            phase(record, settings)
            record.phases.append({"name": phase.__name__, "outcome": "CONTINUE"})
        except gravcal.Error as e:
            record.phases.append({"name": phase.__name__, "outcome": "ERROR", "error": str(e)})
            record.state["error"] = str(e)
            break
    return record


def write_record(record, folder):
    """The record as OpenHTF's JSON output would hold it, with the
    attachments beside it."""
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, record.unit + ".record.json"), "w") as f:
        json.dump(record.to_json(), f, indent=2, default=float)
    for name, data in record.attachments.items():
        with open(os.path.join(folder, record.unit + "." + name), "wb") as f:
            f.write(data)


def openhtf_test(unit, settings):
    """The same station as an openhtf.Test (needs openhtf): one phase that
    runs the station and records every acceptance limit's measured value in
    the dimensioned measurement ``limit_value`` (by limit name) and the
    verdict in ``verdict``, which must equal "pass" (OpenHTF's validator
    decides the outcome); the certificate and the calibration are attached."""
    import openhtf as htf

    @htf.measures(
        htf.Measurement("limit_value").with_dimensions("limit")
        .doc("each acceptance limit's measured value (gravcal check_limits)"),
        htf.Measurement("verdict").equals("pass").doc("gravcal's acceptance verdict"))
    def station_phase(test):
        record = run_station(unit, settings)
        for name, m in record.measurements.items():
            if m["value"] is not None:
                test.measurements.limit_value[name] = m["value"]
        for name, data in record.attachments.items():
            test.attach(name, data)
        test.measurements.verdict = "pass" if record.outcome == "PASS" else "fail"

    return htf.Test(station_phase)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log", nargs="?", help="the unit's calibration session")
    parser.add_argument("--unit", required=True)
    parser.add_argument("--limits", required=True, help="acceptance limits (YAML)")
    parser.add_argument("--config", required=True)
    parser.add_argument("--out", required=True, help="folder for the record and attachments")
    parser.add_argument("--simulate", type=int, help="simulate the session with this seed")
    parser.add_argument("--station", default=None)
    args = parser.parse_args(argv)
    if args.log:
        log = args.log
    elif args.simulate is not None:
        _, log = gravcal.simulate(config=args.config, seed=args.simulate)
    else:
        parser.error("give a LOG or --simulate SEED")
    settings = {"log": log, "config": args.config, "limits": args.limits,
                "station": args.station, "input_file": args.log or "simulated"}
    record = run_station(args.unit, settings)
    write_record(record, args.out)
    failed = [n for n, m in record.measurements.items() if m["outcome"] == "FAIL"]
    print("%s: %s%s" % (args.unit, record.outcome, (": " + ", ".join(failed)) if failed else ""))
    return 0 if record.outcome == "PASS" else 1


if __name__ == "__main__":
    sys.exit(main())
