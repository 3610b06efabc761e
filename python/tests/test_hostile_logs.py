"""Issue 32: the Python package reads the shared hostile logs
(tests/hostile_logs/cases.tsv, also run by tests/hostile_logs_test.cc) with
the same one-line message as `gravcal apply` and `gravcal calibrate`, and
refuses edited calibrations as `gravcal apply` does."""
import json
import os

import numpy as np
import pytest

import gravcal
from conftest import SOURCE_DIR, run_cli

HOSTILE_DIR = os.path.join(SOURCE_DIR, "tests", "hostile_logs")


def hostile_logs():
    cases = []
    with open(os.path.join(HOSTILE_DIR, "cases.tsv")) as f:
        for line in f:
            line = line.rstrip("\n")
            if line and not line.startswith("#"):
                name, _, fragment = line.partition("\t")
                cases.append((name, fragment))
    return cases


CALIBRATION = {
    "method": "twelve_position",
    "accel": {"model": "scale", "bias": [1.0, 2.0, 3.0],
              "matrix": [[0.001, 0.0, 0.0], [0.0, 0.002, 0.0], [0.0, 0.0, 0.003]]},
    "gravity": {"value": 9.81},
}


@pytest.mark.parametrize("name,fragment", hostile_logs())
def test_hostile_log_same_message_as_apply_and_calibrate(tmp_path, name, fragment):
    path = os.path.join(HOSTILE_DIR, name)
    calib = tmp_path / "calib.json"
    calib.write_text(json.dumps(CALIBRATION))
    code, apply_error = run_cli("apply", "--calibration", calib, "--input", path, "--output",
                                tmp_path / "out.csv", ok=False)
    assert code == 1
    code, calibrate_error = run_cli("calibrate", "--input", path, "--output",
                                    tmp_path / "c.json", ok=False)
    assert code == 1
    assert apply_error == calibrate_error
    assert (path + (fragment or ":")) in apply_error
    with pytest.raises(gravcal.Error) as e:
        gravcal.read_log(path)
    assert str(e.value) == apply_error
    assert sorted(os.listdir(tmp_path)) == ["calib.json"]


@pytest.mark.parametrize("edit,key", [
    (lambda j: j["accel"]["matrix"][0].__setitem__(0, 0.0011), "accel.matrix"),
    (lambda j: j["accel"].__setitem__("matrix", [[0.0] * 3] * 3), "accel.matrix"),
    (lambda j: j["accel"].__setitem__("matrix", [[1e-3, 0, 0], [0, 1e-3, 0], [0, 0, -1e-3]]),
     "accel.matrix"),
    (lambda j: j.__setitem__("gyro", {"bias": [0, 0, 0], "matrix": [[1e308, 0, 0], [0, 1e308, 0],
                                                                    [0, 0, 1e308]]}),
     "gyro.matrix"),
])
def test_edited_calibration_same_message_as_apply(tmp_path, edit, key):
    j = json.loads(json.dumps(CALIBRATION))
    j["accel"]["upper"] = [list(row) for row in j["accel"]["matrix"]]
    j["accel"]["rotation"] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    edit(j)
    calib = tmp_path / "calib.json"
    calib.write_text(json.dumps(j))
    log = tmp_path / "raw.csv"
    log.write_text("t,ax,ay,az\n0,1,2,3\n")
    code, expected = run_cli("apply", "--calibration", calib, "--input", log, "--output",
                             tmp_path / "out.csv", ok=False)
    assert code == 1
    assert ("key '%s'" % key) in expected
    with pytest.raises(gravcal.Error) as e:
        gravcal.Calibration.from_json(calib)
    assert str(e.value) == expected
    assert not (tmp_path / "out.csv").exists()


def test_tiny_but_well_conditioned_matrix_is_applied(tmp_path):
    j = json.loads(json.dumps(CALIBRATION))
    j["accel"]["matrix"] = [[1e-120, 0, 0], [0, 1e-120, 0], [0, 0, 1e-120]]
    calib = tmp_path / "calib.json"
    calib.write_text(json.dumps(j))
    a = gravcal.Calibration.from_json(calib).apply(np.array([[2.0, 4.0, 6.0]]))
    np.testing.assert_allclose(a, [[1e-120, 2e-120, 3e-120]], rtol=1e-14, atol=0)


def test_overflowing_correction_is_refused_by_row(tmp_path):
    j = json.loads(json.dumps(CALIBRATION))
    j["accel"]["matrix"] = [[1e100, 0, 0], [0, 1e100, 0], [0, 0, 1e100]]
    calib = tmp_path / "calib.json"
    calib.write_text(json.dumps(j))
    with pytest.raises(gravcal.Error, match=r"^accel: row 1: the corrected sample is not finite"):
        gravcal.Calibration.from_json(calib).apply(np.array([[1.0, 2.0, 3.0], [1e300, 2.0, 3.0]]))
