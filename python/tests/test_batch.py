"""batch from Python equals `gravcal batch` on 100 units (issue 18)."""
import csv

import pytest

import gravcal
from conftest import config_path, read_json, run_cli, strip_times, without_log_file

# Short sessions keep 100 units fast: 4 s poses at 25 Hz.
SHORT = {"sim_hold": 4, "sim_sample_rate": 25, "sim_rotation_time": 2}
UNITS = 100


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fleet")
    logs = []
    cfg = gravcal.config(config_path("twelve_position.yaml"), **SHORT)
    for i in range(UNITS):
        _, log = gravcal.simulate(cfg, seed=100 + i)
        log.to_csv(folder / ("unit%03d.csv" % i))
        logs.append(log)
    return folder, logs


def test_batch_equals_cli(fleet, tmp_path):
    folder, _ = fleet
    cfg = config_path("twelve_position.yaml")
    out = tmp_path / "cli"
    run_cli("batch", "--input-dir", folder, "--config", cfg, "--output-dir", out, "--threads", 2)
    results = gravcal.batch(folder, config=cfg, threads=2)
    assert len(results) == UNITS
    assert [r.unit for r in results] == ["unit%03d" % i for i in range(UNITS)]
    calibrated = 0
    for r in results:
        cli_file = out / (r.unit + ".json")
        assert (r.calibration is not None) == cli_file.exists(), r.unit
        if r.calibration is None:
            continue
        calibrated += 1
        assert r.status == "ok", (r.unit, r.status)
        assert strip_times(r.calibration.to_dict()) == strip_times(read_json(cli_file)), r.unit
    assert calibrated >= UNITS - 5
    # The CLI's state files hold the same content hashes, its summary the
    # same statuses.
    with open(out / "summary.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == UNITS
    for r, row in zip(results, rows):
        state = read_json(out / "batch_state" / (r.unit + ".json"))
        assert state["content_hash"] == r.content_hash, r.unit
        assert (row["unit"], row["status"]) == (r.unit, r.status)


def test_batch_of_logs_in_memory_equals_files(fleet):
    folder, logs = fleet
    cfg = config_path("twelve_position.yaml")
    from_files = gravcal.batch(folder, config=cfg, threads=2)
    units = [{"id": "unit%03d" % i, "log": log} for i, log in enumerate(logs[:20])]
    in_memory = gravcal.batch(units, config=cfg, threads=2)
    for a, b in zip(in_memory, from_files[:20]):
        assert a.unit == b.unit and a.status == b.status
        if a.calibration is not None:
            # A log in memory has no file, so no provenance (file name and
            # content hash); everything else is the same.
            db = strip_times(b.calibration.to_dict())
            assert "log_hash" in db["provenance"]
            assert without_log_file(strip_times(a.calibration.to_dict())) == without_log_file(db)


def test_batch_overrides_and_failures_do_not_raise(fleet):
    folder, _ = fleet
    units = [
        {"path": folder / "unit000.csv", "overrides": {"gravity": 9.81}},
        {"id": "missing", "path": folder / "does_not_exist.csv"},
    ]
    results = gravcal.batch(units, config=config_path("twelve_position.yaml"), threads=1)
    assert results[0].unit == "unit000" and results[0].calibration.gravity.value == 9.81
    assert results[1].calibration is None
    assert "does_not_exist.csv" in results[1].message
