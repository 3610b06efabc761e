"""Guided calibration from your own acquisition loop (gravcal.Recorder).

A real loop reads the sensor (serial, a ROS 2 topic, a test station's
driver) and shows the suggestions to the operator or drives a fixture. Here
a toy unit stands in: it is put exactly where the recorder suggests, with a
made-up bias, scale and white noise, and turned in one step (a jump in the
samples is motion to the detector).

    python3 examples/record_guided.py [configs/twelve_position.yaml]
"""
import sys

import numpy as np

import gravcal

CONFIG = sys.argv[1] if len(sys.argv) > 1 else "configs/twelve_position.yaml"
COUNTS_PER_G = 16384.0
RATE = 100.0


def main():
    rng = np.random.default_rng(1)
    bias = np.array([120.0, -80.0, 40.0])  # counts
    scale = np.array([1.01, 0.99, 1.005])
    recorder = gravcal.Recorder(CONFIG, "accel_bias=0.3mg accel_scale=100ppm")
    up = np.array([0.0, 0.0, 1.0])
    t = 0.0
    moving_until = -1.0
    while not recorder.done and t < 900.0:
        if t < moving_until:  # being turned: anything but still
            accel = rng.normal(0.0, 3000.0, 3)
        else:
            accel = up * COUNTS_PER_G * scale + bias + rng.normal(0.0, 30.0, 3)
        for event in recorder.feed(t, accel):
            if event["event"] == "suggest":
                print("next:", event["instruction"], "hold %.0f s" % event["hold_seconds"])
                up = np.array(event["up"])
                moving_until = t + 2.0
            elif event["event"] == "pose_captured":
                print("captured:", event["up_words"])
        t += 1.0 / RATE
    calibration = recorder.finish()
    print(recorder.done_event["reason"], "after", recorder.done_event["poses"], "poses")
    print("bias (counts):", calibration.accel.bias, "+-", calibration.accel.std.bias)


if __name__ == "__main__":
    main()
