"""noise and discover from Python equal `gravcal noise` / `gravcal discover`."""
import numpy as np
import pytest

import gravcal
from conftest import config_path, read_json, run_cli, strip_times


def test_noise_equals_cli(tmp_path):
    keys = ["--sim_scheme", "six", "--sim_initial_still", "300", "--sim_hold", "5"]
    run_cli("simulate", *keys, "--seed", 4, "--output-dir", tmp_path)
    scale = repr(9.80665 / 16384)
    out = tmp_path / "noise.json"
    run_cli("noise", "--input", tmp_path / "raw.csv", "--nominal_scale", scale,
            "--output", out)
    result = gravcal.noise(tmp_path / "raw.csv", nominal_scale=float(scale))
    assert strip_times(result) == strip_times(read_json(out))
    assert result["accel"]["x"]["white_noise"]["value"] > 0


def test_noise_writes_the_clis_files(tmp_path):
    # A still log whose white noise and random walk show on every axis (so
    # Kalibr's imu.yaml can be written), in m/s^2 and rad/s.
    rate, n = 100.0, 120000
    rng = np.random.default_rng(1)

    def still(white, walk, mean):
        steps = walk / np.sqrt(rate) * rng.standard_normal((n, 3))
        return np.asarray(mean) + white * np.sqrt(rate) * rng.standard_normal((n, 3)) + \
            np.cumsum(steps, axis=0)

    path = tmp_path / "still.csv"
    gravcal.log(np.arange(n) / rate, still(2e-3, 5e-3, [0.0, 0.0, 9.80665]),
                still(2e-4, 5e-4, [0.0, 0.0, 0.0])).to_csv(path)
    units = {"nominal_scale": 1.0, "gyro_nominal_scale": 1.0}
    files = ("kalibr", "handheld", "report")
    run_cli("noise", "--input", path, "--nominal_scale", 1, "--gyro_nominal_scale", 1,
            "--output", tmp_path / "cli.json",
            *[x for f in files for x in ("--" + f, tmp_path / ("cli_" + f))])
    result = gravcal.noise(str(path), **units, **{f: tmp_path / ("py_" + f) for f in files})
    assert strip_times(result) == strip_times(read_json(tmp_path / "cli.json"))
    for f in files:
        cli = (tmp_path / ("cli_" + f)).read_bytes()
        assert (tmp_path / ("py_" + f)).read_bytes() == cli, f
    assert b"accelerometer_random_walk" in (tmp_path / "cli_kalibr").read_bytes()
    assert (tmp_path / "cli_report").read_text().lstrip().lower().startswith("<!doctype html")


def test_noise_kalibr_failure_writes_nothing(tmp_path):
    # 5 s of rest: enough for the curve, too short to show the random walk
    # Kalibr needs. The CLI and Python fail with the same line and leave no
    # file (the texts are made before any file is written).
    rng = np.random.default_rng(2)
    n = 500
    path = tmp_path / "five.csv"
    gravcal.log(np.arange(n) / 100.0, [0.0, 0.0, 9.80665] + 2e-3 * rng.standard_normal((n, 3)),
                2e-4 * rng.standard_normal((n, 3))).to_csv(path)
    files = {"kalibr": tmp_path / "imu.yaml", "report": tmp_path / "noise.html"}
    code, error = run_cli("noise", "--input", path, "--nominal_scale", 1, "--gyro_nominal_scale", 1,
                          "--noise_find_still", "false", "--output", tmp_path / "noise.json",
                          *[x for f, p in files.items() for x in ("--" + f, p)], ok=False)
    assert code == 1 and "Kalibr needs" in error
    with pytest.raises(gravcal.Error) as raised:
        gravcal.noise(str(path), nominal_scale=1.0, gyro_nominal_scale=1.0, noise_find_still=False,
                      **files)
    assert str(raised.value) == error
    assert sorted(p.name for p in tmp_path.iterdir()) == ["five.csv"]


def test_discover_equals_cli(tmp_path):
    cfg = config_path("discovery.yaml")
    run_cli("simulate", "--config", cfg, "--seed", 3, "--sim_hold", 4, "--output-dir", tmp_path)
    out = tmp_path / "discovery.json"
    run_cli("discover", "--config", cfg, "--input", tmp_path / "raw.csv", "--output", out)
    report = tmp_path / "py.html"
    result = gravcal.discover(tmp_path / "raw.csv", config=cfg, report=report)
    assert strip_times(result) == strip_times(read_json(out))
    assert report.read_text().lstrip().lower().startswith("<!doctype html")


def test_discover_bad_config_raises():
    with pytest.raises(gravcal.Error):
        gravcal.discover(t=[0.0, 1.0], accel=[[0, 0, 9.8], [0, 0, 9.8]])
