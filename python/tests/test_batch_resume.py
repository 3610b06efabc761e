"""batch with output_dir writes the folder `gravcal batch` writes and resumes
from it: an interrupted batch computes only the units it had not stored
(issue 34, workflows/batch_folder.h)."""
import csv
import os
import signal
import subprocess
import sys
import time

import pytest

import gravcal
from conftest import config_path, read_json, run_cli, strip_times

UNITS = 12
CONFIG = config_path("twelve_position.yaml")


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    folder = tmp_path_factory.mktemp("resume_fleet")
    cfg = gravcal.config(CONFIG)
    for i in range(UNITS):
        _, log = gravcal.simulate(cfg, seed=300 + i)
        log.to_csv(folder / ("unit%02d.csv" % i))
    return folder


def summary_without_times(path):
    """summary.csv's rows without the wall-clock columns (*_s)."""
    with open(path, newline="") as f:
        return [{k: v for k, v in row.items() if not k.endswith("_s")}
                for row in csv.DictReader(f)]


def dead_pid():
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def test_folder_equals_cli_and_a_second_run_computes_nothing(fleet, tmp_path):
    cli = tmp_path / "cli"
    run_cli("batch", "--input-dir", fleet, "--config", CONFIG, "--output-dir", cli, "--threads", 2)
    out = tmp_path / "py"
    first = gravcal.batch(fleet, config=CONFIG, threads=2, output_dir=out)
    assert [r.skipped for r in first] == [False] * UNITS
    for name in ["summary.csv"] + ["unit%02d.json" % i for i in range(UNITS)]:
        a, b = out / name, cli / name
        assert a.exists() == b.exists(), name
        if name.endswith(".json") and a.exists():
            assert strip_times(read_json(a)) == strip_times(read_json(b)), name
    assert summary_without_times(out / "summary.csv") == summary_without_times(cli / "summary.csv")
    assert "skipped 0" in first.brief_report()

    second = gravcal.batch(fleet, config=CONFIG, threads=2, output_dir=out)
    assert [r.skipped for r in second] == [True] * UNITS
    assert [r.status for r in second] == [r.status for r in first]
    for a, b in zip(first, second):
        if a.calibration is not None:
            assert strip_times(b.calibration.to_dict()) == strip_times(a.calibration.to_dict())
    assert "skipped %d" % UNITS in str(second)
    # The CLI resumes from the folder Python wrote.
    code, _ = run_cli("batch", "--input-dir", fleet, "--config", CONFIG, "--output-dir", out)
    assert code == 0


def test_partial_batch_resumes_with_only_the_missing_units(fleet, tmp_path):
    out = tmp_path / "out"
    whole = gravcal.batch(fleet, config=CONFIG, threads=2, output_dir=out)
    summary = summary_without_times(out / "summary.csv")
    # What a run killed after unit 7 leaves: units 8.. have no result and no
    # state, a write of the killed process is left as a temporary, and the
    # summary is not written.
    missing = ["unit%02d" % i for i in range(8, UNITS)]
    for unit in missing:
        os.remove(out / (unit + ".json"))
        os.remove(out / "batch_state" / (unit + ".json"))
    os.remove(out / "summary.csv")
    stale = ".gravcal-tmp.%d.0123abcd.unit08.json" % dead_pid()
    (out / stale).write_text("{")
    (out / "batch_state" / stale).write_text("{")
    # A changed unit is computed again although its state exists.
    changed = fleet / "unit03.csv"
    original = changed.read_bytes()
    cfg = gravcal.config(CONFIG)
    try:
        _, log = gravcal.simulate(cfg, seed=999)
        log.to_csv(changed)
        resumed = gravcal.batch(fleet, config=CONFIG, threads=2, output_dir=out)
    finally:
        changed.write_bytes(original)
    computed = [r.unit for r in resumed if not r.skipped]
    assert computed == ["unit03"] + missing
    assert not (out / stale).exists() and not (out / "batch_state" / stale).exists()
    for a, b in zip(whole, resumed):
        if a.unit in missing:
            assert strip_times(b.calibration.to_dict()) == strip_times(a.calibration.to_dict())
    assert "skipped %d" % (UNITS - 1 - len(missing)) in resumed.brief_report()
    # Back to the original unit 3: the folder resumes to the first summary.
    again = gravcal.batch(fleet, config=CONFIG, threads=2, output_dir=out)
    assert [r.unit for r in again if not r.skipped] == ["unit03"]
    assert summary_without_times(out / "summary.csv") == summary


def test_killed_python_batch_resumes(fleet, tmp_path):
    out = tmp_path / "killed"
    code = ("import gravcal, sys\n"
            "gravcal.batch(sys.argv[1], config=sys.argv[2], threads=1, output_dir=sys.argv[3])\n")
    env = dict(os.environ)
    p = subprocess.Popen([sys.executable, "-c", code, str(fleet), CONFIG, str(out)], env=env)
    state = out / "batch_state"

    def stored_units():
        # Not the temporaries of a write in flight (".gravcal-tmp....json").
        return sorted(n[:-5] for n in os.listdir(state)
                      if n.endswith(".json") and not n.startswith("."))

    deadline = time.time() + 60
    while p.poll() is None and time.time() < deadline:
        if state.is_dir() and stored_units():
            p.send_signal(signal.SIGKILL)
            break
        time.sleep(0.002)
    p.wait()
    stored = stored_units()
    assert stored, "the killed run stored no unit"
    resumed = gravcal.batch(fleet, config=CONFIG, threads=2, output_dir=out)
    # Every unit the killed run stored is reused, every other one computed.
    assert sorted(r.unit for r in resumed if r.skipped) == stored
    assert len(resumed) == UNITS
    # The killed run's temporaries are gone.
    for folder in (out, state):
        assert not [n for n in os.listdir(folder) if n.startswith(".gravcal-tmp.")]
    assert len((out / "summary.csv").read_text().splitlines()) == UNITS + 1
