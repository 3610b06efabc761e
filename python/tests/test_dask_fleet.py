"""A fleet calibrated on a Dask cluster through the Python package (the
recipe of docs/workflows/batch_cluster.md): the results equal `gravcal
batch`'s, and a unit that fails is reported in its result without stopping
the others. Skipped when dask.distributed is missing (Debian:
python3-dask python3-distributed)."""
import os
import time

import pytest

import gravcal
from conftest import config_path, read_json, run_cli, strip_times, without_log_file

distributed = pytest.importorskip("distributed")
# Debian's tornado 6.2 under distributed 2022.12 warns on every loop start.
pytestmark = pytest.mark.filterwarnings("ignore:make_current is deprecated:DeprecationWarning")

SHORT = {"sim_hold": 4, "sim_sample_rate": 25, "sim_rotation_time": 2}
UNITS = 6


def calibrate_unit(path, config):
    """One unit: its calibration as a dict, or its error; never raises, so
    one bad log does not fail the fleet."""
    unit = os.path.splitext(os.path.basename(path))[0]
    try:
        calibration = gravcal.calibrate(path, config=config)
    except gravcal.Error as e:
        return {"unit": unit, "calibration": None, "error": str(e)}
    return {"unit": unit, "calibration": calibration.to_dict(), "error": None}


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    folder = tmp_path_factory.mktemp("dask_fleet")
    cfg = gravcal.config(config_path("twelve_position.yaml"), **SHORT)
    for i in range(UNITS):
        _, log = gravcal.simulate(cfg, seed=300 + i)
        log.to_csv(folder / ("unit%d.csv" % i))
    # A unit whose log is cut in the middle of its header row.
    (folder / "unit_broken.csv").write_text("t,ax,ay\n0.0,1.0\n")
    return folder


def test_dask_fleet_equals_cli_batch(fleet, tmp_path):
    cfg = config_path("twelve_position.yaml")
    out = tmp_path / "cli"
    # The CLI ends with an error when a unit failed, after the others.
    code, error = run_cli("batch", "--input-dir", fleet, "--config", cfg, "--output-dir", out,
                          "--threads", 2, ok=False)
    assert code != 0 and "1 of 7 units failed" in error
    paths = sorted(str(p) for p in fleet.glob("*.csv"))
    start = time.monotonic()
    # Threads in one process: the calibration releases the GIL.
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        futures = client.map(calibrate_unit, paths, config=cfg)
        results = client.gather(futures)
    assert time.monotonic() - start < 60
    assert [r["unit"] for r in results] == [os.path.splitext(os.path.basename(p))[0]
                                            for p in paths]
    broken = [r for r in results if r["unit"] == "unit_broken"]
    assert len(broken) == 1 and broken[0]["calibration"] is None
    assert "unit_broken.csv" in broken[0]["error"]
    assert not (out / "unit_broken.json").exists()
    calibrated = 0
    for r in results:
        if r["unit"] == "unit_broken":
            continue
        assert r["error"] is None, r
        cli = read_json(out / (r["unit"] + ".json"))
        assert without_log_file(strip_times(r["calibration"])) == \
            without_log_file(strip_times(cli)), r["unit"]
        calibrated += 1
    assert calibrated == UNITS
