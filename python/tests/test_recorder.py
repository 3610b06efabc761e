"""gravcal.Recorder (issue 37): a loop that follows the suggestions meets
the targets, and finish() equals calibrate on the recorded log."""
import numpy as np

import gravcal
from conftest import config_path

TWELVE = config_path("twelve_position.yaml")


def run(follow):
    rng = np.random.default_rng(3)
    bias = np.array([120.0, -80.0, 40.0])
    recorder = gravcal.Recorder(TWELVE, "accel_bias=0.3mg accel_scale=100ppm", max_time=200)
    up, t, moving_until, events = np.array([0.0, 0.0, 1.0]), 0.0, -1.0, []
    while not recorder.done:
        accel = (rng.normal(0.0, 3000.0, 3) if t < moving_until
                 else up * 16384.0 + bias + rng.normal(0.0, 30.0, 3))
        for e in recorder.feed(t, accel, [0.0, 0.0, 0.0]):
            events.append(e)
            if e["event"] == "suggest":
                up = np.array(e["up"]) if follow else np.array([0.0, 0.0, 1.0])
                moving_until = t + 2.0
        t += 0.01
    return recorder, events


def test_following_meets_targets_and_equals_calibrate():
    recorder, events = run(True)
    calibration = recorder.finish()
    assert recorder.done_event["reason"] == "targets_met"
    assert any(e["event"] == "pose_captured" for e in events)
    again = gravcal.calibrate(gravcal.log(**_columns(recorder.log_csv)), config=TWELVE)
    assert np.array_equal(again.accel.bias, calibration.accel.bias)
    assert np.array_equal(again.accel.matrix, calibration.accel.matrix)


def test_one_face_never_meets_targets():
    recorder, events = run(False)
    assert recorder.done and not any(e["event"] == "sigma" and e["targets_met"] for e in events)
    try:
        recorder.finish()
    except gravcal.Error as error:  # too few distinct poses to calibrate: said
        assert "positions" in str(error)
    assert recorder.done_event["reason"] == "max_time"
    assert all("+Z up" in u["reason"] for u in recorder.done_event["undetermined"])
    assert recorder.done_event["undetermined"]


def _columns(csv):
    rows = np.array([[float(x) for x in line.split(",")] for line in csv.splitlines()[1:]])
    return {"t": rows[:, 0], "accel": rows[:, 1:4], "gyro": rows[:, 4:7]}
