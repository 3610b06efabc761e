"""Every bad input raises gravcal.Error with the CLI's message (issue 18)."""
import json
import os
import stat

import numpy as np
import pytest

import gravcal
from conftest import config_path, run_cli


def test_error_is_a_value_error():
    assert issubclass(gravcal.Error, ValueError)


def good_arrays(n=10):
    t = np.arange(n) * 0.01
    accel = np.tile([0.0, 0.0, 9.8], (n, 1))
    return t, accel


@pytest.mark.parametrize("change,message", [
    (lambda t, a: (t, a[:, :2]), "accel: expected an array of shape (N, 3), got shape (10, 2)"),
    (lambda t, a: (t, a[0]), "accel: expected an array of shape (N, 3), got shape (3,)"),
    (lambda t, a: (t, a[:9]), "accel: 9 samples, but t has 10"),
    (lambda t, a: (t.reshape(2, 5), a), "t: expected an array of shape (N,), got shape (2, 5)"),
    (lambda t, a: (t, np.where(np.arange(30).reshape(10, 3) == 7, np.nan, a)),
     "arrays: sample 2: accelerometer is not finite"),
    (lambda t, a: (np.where(np.arange(10) == 4, 0.0, t), a),
     "arrays: sample 4: time does not increase"),
    (lambda t, a: (np.where(np.arange(10) == 0, np.inf, t), a),
     "arrays: sample 0: time is not finite"),
    (lambda t, a: (t, [["a", "b", "c"]] * 10), "accel: not an array of numbers"),
    (lambda t, a: (t[:0], a[:0]), "arrays: no samples"),
])
def test_bad_arrays_are_refused_by_name(change, message):
    t, accel = change(*good_arrays())
    with pytest.raises(gravcal.Error) as e:
        gravcal.calibrate(t=t, accel=accel)
    assert str(e.value) == message


def test_bad_gyro_and_temp():
    t, accel = good_arrays()
    with pytest.raises(gravcal.Error, match=r"^gyro: expected an array of shape \(N, 3\)"):
        gravcal.log(t, accel, gyro=np.zeros((10, 4)))
    with pytest.raises(gravcal.Error, match=r"^temp: 3 samples, but t has 10$"):
        gravcal.log(t, accel, temp=np.zeros(3))
    with pytest.raises(gravcal.Error, match=r"^arrays: sample 1: gyroscope is not finite$"):
        g = np.zeros((10, 3))
        g[1, 2] = np.nan
        gravcal.log(t, accel, gyro=g)


def test_dataframe_missing_column():
    pandas = pytest.importorskip("pandas")
    frame = pandas.DataFrame({"t": [0.0, 1.0], "ax": [0.0, 0.0], "ay": [0.0, 0.0]})
    with pytest.raises(gravcal.Error, match="column 'az' is missing"):
        gravcal.calibrate(frame)


def cli_error(*args):
    code, error = run_cli(*args, ok=False)
    assert code != 0 and error
    return error


def test_missing_file_same_message_as_cli(tmp_path):
    missing = tmp_path / "missing.csv"
    expected = cli_error("calibrate", "--input", missing, "--output", tmp_path / "x.json")
    with pytest.raises(gravcal.Error) as e:
        gravcal.calibrate(missing)
    assert str(e.value) == expected
    with pytest.raises(gravcal.Error) as e:
        gravcal.read_log(missing)
    assert str(e.value) == expected


def test_bad_config_file_same_message_as_cli(tmp_path, session_dir):
    bad = tmp_path / "bad.yaml"
    bad.write_text("method: twelve_position\ngravty: 9.8\n")
    expected = cli_error("calibrate", "--config", bad, "--input", session_dir / "raw.csv",
                         "--output", tmp_path / "x.json")
    with pytest.raises(gravcal.Error) as e:
        gravcal.calibrate(session_dir / "raw.csv", config=bad)
    assert str(e.value) == expected


def test_bad_key_value_same_message_as_cli(tmp_path, session_dir):
    # The CLI prefixes "command line: " to a flag's error; the rest is the same.
    expected = cli_error("calibrate", "--loss", "squared", "--input", session_dir / "raw.csv",
                         "--output", tmp_path / "x.json")
    with pytest.raises(gravcal.Error) as e:
        gravcal.calibrate(session_dir / "raw.csv", loss="squared")
    assert "command line: " + str(e.value) == expected
    with pytest.raises(gravcal.Error) as e:
        gravcal.calibrate(session_dir / "raw.csv", config={"no_such_key": 1})
    assert "no_such_key" in str(e.value)


def test_too_few_poses_same_message_as_cli(tmp_path):
    _, log = gravcal.simulate(seed=1, sim_hold=3, sim_scheme="six")
    still = gravcal.log(log.t[:1500], log.accel[:1500])
    raw = tmp_path / "still.csv"
    still.to_csv(raw)
    cfg = config_path("twelve_position.yaml")
    expected = cli_error("calibrate", "--config", cfg, "--input", raw, "--output",
                         tmp_path / "x.json")
    with pytest.raises(gravcal.Error) as e:
        gravcal.calibrate(raw, config=cfg)
    assert str(e.value) == expected


def test_method_key_check_same_message_as_cli(tmp_path, session_dir):
    # A key the method does not use is refused by Config::IsValid.
    expected = cli_error("calibrate", "--method", "ten_position", "--gyro_model", "full",
                         "--input", session_dir / "raw.csv", "--output", tmp_path / "x.json")
    with pytest.raises(gravcal.Error) as e:
        gravcal.calibrate(session_dir / "raw.csv", method="ten_position", gyro_model="full")
    assert str(e.value) == expected


def test_bad_calibration_file(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"method": "x"}')
    expected = cli_error("apply", "--calibration", bad, "--input", bad, "--output",
                         tmp_path / "o.csv")
    with pytest.raises(gravcal.Error) as e:
        gravcal.Calibration.from_json(bad)
    assert str(e.value) == expected


def test_apply_refuses_bad_arrays(py_calibration):
    with pytest.raises(gravcal.Error, match=r"^accel: expected an array of shape \(N, 3\)"):
        py_calibration.apply(np.zeros((4, 2)))
    with pytest.raises(gravcal.Error, match="^accel: row 1 is not finite$"):
        py_calibration.apply(np.array([[0.0, 0, 0], [np.nan, 0, 0]]))
    with pytest.raises(gravcal.Error, match="^t: 2 samples, but accel has 1$"):
        py_calibration.apply(np.zeros((1, 3)), t=np.zeros(2))


def test_destinations_are_checked_before_the_work(tmp_path):
    """The destination contract (docs/data_contract.md#destinations): an
    input is never overwritten, a FIFO never replaced, '-' never a file; a
    symbolic link's target is replaced."""
    log = tmp_path / "s.csv"
    log.write_text("precious")
    with pytest.raises(gravcal.Error) as e:
        gravcal.discover(log, report=log)
    assert str(e.value).startswith(str(log) + ": report is the same file as the input log")
    with pytest.raises(gravcal.Error) as e:
        gravcal.noise(log, report=tmp_path / "." / "s.csv")
    assert "same file as the input log" in str(e.value)
    assert log.read_text() == "precious"
    fifo = tmp_path / "plan.json"
    os.mkfifo(fifo)
    with pytest.raises(gravcal.Error) as e:
        gravcal.plan(config_path("twelve_position.yaml"), output=fifo)
    assert str(e.value) == str(fifo) + ": exists and is a FIFO: gravcal replaces only regular files"
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)
    with pytest.raises(gravcal.Error):
        gravcal.plan(config_path("twelve_position.yaml"), output="-")
    (tmp_path / "real").mkdir()
    link = tmp_path / "link.json"
    link.symlink_to("real/plan.json")
    gravcal.plan(config_path("twelve_position.yaml"), output=link,
                 target="accel_bias=0.5mg accel_scale=100ppm", accel_noise_density=0.002)
    assert link.is_symlink()
    assert json.loads((tmp_path / "real" / "plan.json").read_text())["poses"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.json", "plan.json", "real", "s.csv"]
