"""Issue 35: the thermal model from Python (thermal_model, thermal_evaluate)
and its PX4 export with the device ids."""
import json

import numpy as np
import pytest

import gravcal
from conftest import config_path, run_cli


@pytest.fixture(scope="module")
def thermal_calibration(tmp_path_factory):
    """An SI twelve-position calibration with a thermal section added: a
    cubic accelerometer bias, a linear gyroscope bias, an undetermined
    accelerometer scale coefficient."""
    d = tmp_path_factory.mktemp("thermal")
    cfg = config_path("twelve_position_gyro.yaml")
    run_cli("simulate", "--config", cfg, "--sim_raw_counts", "false", "--seed", 5,
            "--output-dir", d)
    run_cli("calibrate", "--config", cfg, "--input", d / "raw.csv", "--output", d / "cal.json")
    cal = json.loads((d / "cal.json").read_text())

    def term(order, rows, std=None):
        n = len(rows)
        return {"order": order, "max_order": 3, "selection": "given",
                "components": ["x", "y", "z"][:n],
                "unit": ["raw/degC^%d" % k for k in range(1, order + 1)],
                "coefficients": rows,
                "std": std if std is not None else [[1e-6] * order] * n,
                "determined": [[c is not None for c in r] for r in rows]}

    cal["thermal"] = {
        "reference_temperature": 25.0, "valid_range": [0.0, 50.0], "temperature_unit": "degC",
        "lag_time_constant": {"value": 0.0, "std": None, "estimated": False, "unit": "s"},
        "accel": {"bias": term(3, [[2e-3, 4e-5, -8e-7], [-1.5e-3, 2e-5, 5e-7],
                                   [3e-3, -6e-5, 1e-6]]),
                  "scale": term(1, [[1e-4], [None], [5e-5]], [[1e-6], [None], [1e-6]])},
        "gyro": {"bias": term(1, [[2.6e-4], [-1e-4], [1.5e-4]])},
        "notes": []}
    path = d / "thermal.json"
    path.write_text(json.dumps(cal))
    return str(path)


def test_thermal_model_and_evaluate(thermal_calibration):
    m = gravcal.thermal_model(thermal_calibration)
    assert m["active"]
    assert m["min_temperature"] == 0.0 and m["max_temperature"] == 50.0
    bias = m["accel"]["bias"]
    assert bias["order"] == 3
    np.testing.assert_allclose(bias["coefficients"][0], [2e-3, 4e-5, -8e-7])
    assert np.isnan(m["accel"]["scale"]["coefficients"][1, 0])  # undetermined
    values, std = gravcal.thermal_evaluate(thermal_calibration, "accel", "bias", [25.0, 35.0, 80.0])
    x = 10.0
    assert values[0, 0] == 0.0
    assert values[1, 0] == pytest.approx(2e-3 * x + 4e-5 * x**2 - 8e-7 * x**3)
    # Clamped to the valid range, as the correction clamps.
    x = 25.0
    assert values[2, 0] == pytest.approx(2e-3 * x + 4e-5 * x**2 - 8e-7 * x**3)
    assert values.shape == std.shape == (3, 3)
    with pytest.raises(gravcal.Error, match="quantity"):
        gravcal.thermal_evaluate(thermal_calibration, "accel", "offset", [25.0])


def test_px4_export_needs_the_device_ids(thermal_calibration):
    with pytest.raises(gravcal.Error, match="--accel_device_id"):
        gravcal.export(thermal_calibration, "px4")
    result = gravcal.export(thermal_calibration, "px4", accel_device_id=2818058,
                            gyro_device_id=2818314)
    text = result["files"][0]["text"]
    assert "\tTC_A0_ID\t2818058\t6" in text
    assert "\tTC_G0_X1_0\t" in text
    assert any("scale against temperature" in d for d in result["dropped"])
    dropped = gravcal.export(thermal_calibration, "px4", drop_thermal=True)
    assert "TC_A0_ID" not in dropped["files"][0]["text"]
