"""Shared fixtures: the CLI next to the module, the source tree, and helpers
that run the CLI and compare its JSON with the Python results."""
import json
import os
import subprocess

import pytest

import gravcal

CLI = os.environ.get("GRAVCAL_CLI", "gravcal")
SOURCE_DIR = os.environ.get("GRAVCAL_SOURCE_DIR",
                            os.path.dirname(os.path.dirname(os.path.dirname(__file__))))
REAL_DATA_DIR = os.environ.get("GRAVCAL_REAL_DATA_DIR",
                               os.path.join(SOURCE_DIR, "..", "shared", "data", "real"))


def config_path(name):
    return os.path.join(SOURCE_DIR, "configs", name)


def run_cli(*args, ok=True, stdout=False):
    """Runs `gravcal args...`; returns (exit code, the one-line error or '')
    (and what it printed on stdout, with stdout=True)."""
    p = subprocess.run([CLI] + [str(a) for a in args], capture_output=True, text=True)
    if ok and p.returncode != 0:
        raise AssertionError("gravcal %s failed: %s" % (" ".join(map(str, args)), p.stderr))
    if stdout:
        return p.stdout
    error = ""
    for line in p.stderr.splitlines():
        if line.startswith("gravcal: error: "):
            error = line[len("gravcal: error: "):]
    return p.returncode, error


def strip_times(x):
    """The JSON without its wall-clock fields (as scripts/golden_outputs.sh)."""
    if isinstance(x, dict):
        return {k: strip_times(v) for k, v in x.items()
                if not (k.endswith("time_s") or k.endswith("_seconds") or k == "seconds")}
    if isinstance(x, list):
        return [strip_times(v) for v in x]
    return x


def without_log_file(d):
    """The calibration dict without the log file's name and hash (a log made
    from arrays has none; everything else must agree)."""
    d = dict(d)
    provenance = dict(d.get("provenance", {}))
    provenance.pop("log_file", None)
    provenance.pop("log_hash", None)
    d["provenance"] = provenance
    return d


def read_json(path):
    with open(path) as f:
        return json.load(f)


@pytest.fixture(scope="session")
def session_dir(tmp_path_factory):
    """`gravcal simulate` of the twelve-position gyro config, seed 5."""
    out = tmp_path_factory.mktemp("sim")
    run_cli("simulate", "--config", config_path("twelve_position_gyro.yaml"), "--seed", 5,
            "--output-dir", out)
    return out


@pytest.fixture(scope="session")
def cli_calibration(session_dir):
    path = session_dir / "cli.json"
    run_cli("calibrate", "--config", config_path("twelve_position_gyro.yaml"), "--input",
            session_dir / "raw.csv", "--output", path)
    return path


@pytest.fixture(scope="session")
def py_calibration(session_dir):
    return gravcal.calibrate(str(session_dir / "raw.csv"),
                             config=config_path("twelve_position_gyro.yaml"))
