"""apply equals `gravcal apply`; simulate equals `gravcal simulate` (issue 18)."""
import json

import numpy as np
import pytest

import gravcal
from conftest import config_path, read_json, run_cli


def test_apply_equals_cli(session_dir, cli_calibration):
    out = session_dir / "corrected.csv"
    run_cli("apply", "--calibration", cli_calibration, "--input", session_dir / "raw.csv",
            "--output", out)
    cli = gravcal.read_log(out)
    raw = gravcal.read_log(session_dir / "raw.csv")
    cal = gravcal.Calibration.from_json(cli_calibration)
    accel, gyro = cal.apply(raw.accel, raw.gyro, temp=raw.temp, t=raw.t)
    assert accel.shape == raw.accel.shape and gyro.shape == raw.gyro.shape
    np.testing.assert_array_equal(accel, cli.accel)
    np.testing.assert_array_equal(gyro, cli.gyro)
    # Accelerometer only: one array back.
    np.testing.assert_array_equal(cal.apply(raw.accel), cli.accel)


def test_apply_with_every_effect_equals_cli(tmp_path, session_dir, cli_calibration):
    # The CLI's calibration with every effect the corrector applies switched
    # on (temperature, drift, quadratic, g-sensitivity): gravcal apply and
    # Calibration.apply go through the same row step, so the numbers agree
    # bit for bit, and the effects do change them.
    d = read_json(cli_calibration)
    d["effects"] = {
        "reference_temperature": 25.0, "reference_time": 30.0,
        "accel_temperature_bias": {"value": [0.002, -0.003, 0.004]},
        "accel_temperature_scale": {"value": [1e-4, -2e-4, 5e-5]},
        "accel_bias_drift": {"value": [1e-4, -2e-4, 3e-4]},
        "accel_quadratic_nonlinearity": {"value": [1e-3, -2e-3, 1.5e-3]},
        "gyro_g_sensitivity": {"value": [0.05, -0.02, 0.01, 0.02, 0.06, -0.04, 0.0, 0.02, -0.03]},
        "gyro_temperature_bias": {"value": [0.5, -0.4, 0.3]},
        "gyro_bias_drift": {"value": [1e-2, -2e-2, 5e-3]},
    }
    path = tmp_path / "effects.json"
    path.write_text(json.dumps(d))
    out = tmp_path / "corrected.csv"
    run_cli("apply", "--calibration", path, "--input", session_dir / "raw.csv", "--output", out)
    cli = gravcal.read_log(out)
    raw = gravcal.read_log(session_dir / "raw.csv")
    accel, gyro = gravcal.Calibration.from_json(path).apply(raw.accel, raw.gyro, temp=raw.temp,
                                                            t=raw.t)
    np.testing.assert_array_equal(accel, cli.accel)
    np.testing.assert_array_equal(gyro, cli.gyro)
    plain_accel, plain_gyro = gravcal.Calibration.from_json(cli_calibration).apply(
        raw.accel, raw.gyro)
    assert np.abs(accel - plain_accel).max() > 1e-4
    assert np.abs(gyro - plain_gyro).max() > 1e-6


def test_apply_of_a_fresh_calibration_equals_cli(session_dir, cli_calibration, py_calibration):
    raw = gravcal.read_log(session_dir / "raw.csv")
    from_file = gravcal.Calibration.from_json(cli_calibration)
    np.testing.assert_array_equal(py_calibration.apply(raw.accel), from_file.apply(raw.accel))


def test_apply_is_the_model(py_calibration):
    raw = np.array([[100.0, -200.0, 16000.0], [0.5, 1.5, -2.5]])
    m = py_calibration.accel.matrix
    b = py_calibration.accel.bias
    np.testing.assert_allclose(py_calibration.apply(raw), (raw - b) @ m.T, rtol=1e-12)


def test_simulate_equals_cli(tmp_path):
    cfg = config_path("twelve_position_gyro.yaml")
    run_cli("simulate", "--config", cfg, "--seed", 7, "--output-dir", tmp_path)
    truth, log, files = gravcal.simulate(config=cfg, seed=7, return_files=True)
    assert truth == read_json(tmp_path / "truth.json")
    cli = gravcal.read_log(tmp_path / "raw.csv")
    for name in ("t", "accel", "gyro", "temp"):
        np.testing.assert_array_equal(getattr(log, name), getattr(cli, name), err_msg=name)
    assert files["attitudes.csv"] == (tmp_path / "attitudes.csv").read_text()
    # The log written from Python is the CLI's file, byte for byte.
    log.to_csv(tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "raw.csv").read_bytes()


def test_simulate_rate_table_writes_segments(tmp_path):
    cfg = config_path("rate_table.yaml")
    run_cli("simulate", "--config", cfg, "--sim_motion", "rate_table", "--seed", 2,
            "--output-dir", tmp_path)
    truth, log, files = gravcal.simulate(cfg, 2, return_files=True, sim_motion="rate_table")
    assert files["segments.csv"] == (tmp_path / "segments.csv").read_text()
    assert truth == read_json(tmp_path / "truth.json")


def test_simulate_is_deterministic_and_seeded():
    a = gravcal.simulate(seed=3, sim_hold=2)[1]
    b = gravcal.simulate(seed=3, sim_hold=2)[1]
    c = gravcal.simulate(seed=4, sim_hold=2)[1]
    np.testing.assert_array_equal(a.accel, b.accel)
    assert not np.array_equal(a.accel, c.accel)


def test_log_arrays_are_read_only_views():
    _, log = gravcal.simulate(seed=1, sim_hold=2)
    assert log.accel.shape == (len(log), 3) and log.t.shape == (len(log),)
    with pytest.raises(ValueError):
        log.accel[0, 0] = 1.0


def test_calibrate_apply_export_make_no_json_text(session_dir, cli_calibration):
    # Issue 34: a result made in memory reaches its corrector and the
    # exporters directly; JSON text is made only when asked for.
    raw = gravcal.read_log(session_dir / "raw.csv")
    before = gravcal._gravcal._json_conversions()
    cal = gravcal.calibrate(raw, config=config_path("twelve_position_gyro.yaml"))
    accel, gyro = cal.apply(raw.accel, raw.gyro)
    exported = {to: gravcal.export(cal, to, name="unit") for to in ("c",)}
    assert gravcal._gravcal._json_conversions() == before
    # The same numbers as through the CLI's file, and the same files as
    # through the result's own JSON text (which asking for makes).
    file_accel, file_gyro = gravcal.Calibration.from_json(cli_calibration).apply(
        raw.accel, raw.gyro)
    np.testing.assert_array_equal(accel, file_accel)
    np.testing.assert_array_equal(gyro, file_gyro)
    from_text = gravcal.Calibration.from_json_text(cal.to_json())
    assert gravcal._gravcal._json_conversions() > before
    for to, result in exported.items():
        assert result["files"] == gravcal.export(from_text, to, name="unit")["files"], to
