"""calibrate from Python equals `gravcal calibrate` (issue 18)."""
import os

import numpy as np
import pytest

import gravcal
from conftest import REAL_DATA_DIR, config_path, read_json, run_cli, strip_times, without_log_file


def test_file_equals_cli_json(session_dir, cli_calibration, py_calibration):
    assert strip_times(py_calibration.to_dict()) == strip_times(read_json(cli_calibration))


def test_attributes_are_the_json(py_calibration):
    d = py_calibration.to_dict()
    assert isinstance(py_calibration.accel.bias, np.ndarray)
    np.testing.assert_array_equal(py_calibration.accel.bias, d["accel"]["bias"])
    np.testing.assert_array_equal(py_calibration.accel.std.bias, d["accel"]["std"]["bias"])
    cov = np.asarray(py_calibration.accel.covariance)
    n = len(d["accel"]["covariance"]["parameters"])
    assert cov.shape == (n, n)
    np.testing.assert_array_equal(cov, d["accel"]["covariance"]["matrix"])
    assert py_calibration.accel.covariance.parameters == d["accel"]["covariance"]["parameters"]
    assert py_calibration.gyro.matrix.shape == (3, 3)
    assert py_calibration.warnings == d.get("warnings", [])
    assert py_calibration.method == "twelve_position"


def test_to_json_round_trip(tmp_path, py_calibration):
    path = tmp_path / "calib.json"
    py_calibration.to_json(path)
    assert path.read_text() == py_calibration.to_json()
    back = gravcal.Calibration.from_json(path)
    assert back.to_dict() == py_calibration.to_dict()
    assert back.to_json() == py_calibration.to_json()


def test_from_json_reads_the_cli_file(cli_calibration):
    cal = gravcal.Calibration.from_json(cli_calibration)
    assert cal.to_json() == cli_calibration.read_text()


def test_arrays_dataframe_and_file_agree(session_dir, py_calibration):
    log = gravcal.read_log(session_dir / "raw.csv")
    cfg = config_path("twelve_position_gyro.yaml")
    from_arrays = gravcal.calibrate(t=np.array(log.t), accel=np.array(log.accel),
                                    gyro=np.array(log.gyro), temp=np.array(log.temp), config=cfg)
    from_file = without_log_file(strip_times(py_calibration.to_dict()))
    assert without_log_file(strip_times(from_arrays.to_dict())) == from_file
    pandas = pytest.importorskip("pandas")
    frame = log.to_dataframe()
    assert isinstance(frame, pandas.DataFrame)
    from_frame = gravcal.calibrate(frame, config=cfg)
    assert without_log_file(strip_times(from_frame.to_dict())) == from_file


def test_config_dict_and_keywords_equal_the_yaml(session_dir):
    raw = session_dir / "raw.csv"
    from_yaml = gravcal.calibrate(raw, config=config_path("twelve_position.yaml"), gravity=9.81)
    keys = {"method": "twelve_position", "format": "csv", "gravity": 9.81, "window": 1.0,
            "threshold_factor": 6.0, "min_duration": 2.0, "settle": 0.3,
            "parameterization": "scale_misalignment", "solver": "ceres", "loss": "none",
            "covariance": True, "output_covariance": True,
            "pose_noise": "batch_means", "pose_variance": True,
            "pose_disturbance_prior": 0.0005, "pose_disturbance_prior_dof": 1}
    from_dict = gravcal.calibrate(raw, config=keys)
    assert strip_times(from_dict.to_dict()) == strip_times(from_yaml.to_dict())
    assert from_dict.gravity.value == 9.81
    # The same as the CLI with the key as a flag.
    out = session_dir / "cli_gravity.json"
    run_cli("calibrate", "--config", config_path("twelve_position.yaml"), "--gravity", "9.81",
            "--input", raw, "--output", out)
    assert strip_times(read_json(out)) == strip_times(from_yaml.to_dict())


@pytest.mark.parametrize("config,path", [
    ("ahrs_static_poses.yaml", "ahrs_static_poses/imu_good1.txt"),
    ("mpu6050_ten_pose.yaml", "mpu6050_ten_pose/session.csv"),
])
def test_real_recording_equals_cli(tmp_path, config, path):
    raw = os.path.join(REAL_DATA_DIR, path)
    if not os.path.exists(raw):
        pytest.skip("real recording %s is not here" % raw)
    out = tmp_path / "cli.json"
    run_cli("calibrate", "--config", config_path(config), "--input", raw, "--output", out)
    cal = gravcal.calibrate(raw, config=config_path(config))
    assert strip_times(cal.to_dict()) == strip_times(read_json(out))


def test_threads_give_the_same_result(session_dir, py_calibration):
    # The GIL is released during the solve: calibrations on threads must not
    # interfere.
    from concurrent.futures import ThreadPoolExecutor
    raw = str(session_dir / "raw.csv")
    cfg = config_path("twelve_position_gyro.yaml")
    with ThreadPoolExecutor(2) as pool:
        results = list(pool.map(lambda _: gravcal.calibrate(raw, config=cfg), range(4)))
    for r in results:
        assert strip_times(r.to_dict()) == strip_times(py_calibration.to_dict())
