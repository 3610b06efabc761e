"""Issue 38: several IMUs at once from Python: a simulated plate calibrated
with the shipped multi-IMU config, the rotations and time offsets against
the truth, the permuted unit named, a bad table refused."""
import json

import numpy as np
import pytest

import gravcal
from conftest import config_path


def test_plate_is_calibrated_and_the_permuted_unit_named(tmp_path):
    csv, truth_text = gravcal._gravcal.simulate_plate(imus=3, seed=4, permuted_imu=2, mounting="aligned",
                                                      hold_seconds=4.0)
    table = tmp_path / "plate.csv"
    table.write_text(csv)
    out = gravcal._gravcal.calibrate_multi_imu(str(table), config_path("multi_imu.yaml"))
    assembly = json.loads(out["assembly"])
    truth = json.loads(truth_text)
    assert sorted(out["calibrations"]) == ["imu0", "imu1", "imu2"]
    assert json.loads(out["calibrations"]["imu1"])["method"] == "multi_imu"
    assert any("imu2 looks rotated 90 degrees about z from imu0" in w
               for w in assembly["warnings"])
    for i in (1, 2):
        est = assembly["imus"][i]
        offset = truth["imus"][i]["clock_offset"]
        assert abs(est["time_offset"] - offset) < 4 * est["time_offset_sigma"]
        r = np.array(est["rotation"]) .T @ np.array(truth["imus"][i]["rotation_to_reference"])
        angle = np.arccos(np.clip((np.trace(r) - 1) / 2, -1, 1))
        assert angle < 4 * max(est["rotation_sigma"]) * np.sqrt(3)


def test_bad_table_is_refused(tmp_path):
    table = tmp_path / "bad.csv"
    table.write_text("t,x\n0,1\n")
    with pytest.raises(gravcal.Error, match="found no IMU columns"):
        gravcal._gravcal.calibrate_multi_imu(str(table), config_path("multi_imu.yaml"))
