"""noise and discover from Python equal `gravcal noise` / `gravcal discover`."""
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
