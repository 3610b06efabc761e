"""A result owns its text (issue 34): Calibration.brief_report() is the line
`gravcal calibrate` prints, full_report() / str() every estimate with its
standard deviation."""
import subprocess

import pytest

import gravcal
from conftest import CLI, config_path


def test_brief_report_is_the_cli_summary_line(session_dir, py_calibration, tmp_path):
    out = tmp_path / "cal.json"
    p = subprocess.run([CLI, "calibrate", "--config", config_path("twelve_position_gyro.yaml"),
                        "--input", str(session_dir / "raw.csv"), "--output", str(out)],
                       capture_output=True, text=True, check=True)
    line = [l for l in p.stderr.splitlines() if l.endswith("; wrote " + str(out))]
    assert len(line) == 1, p.stderr
    brief = py_calibration.brief_report()
    assert line[0] == "gravcal: %s; wrote %s" % (brief, out)
    assert brief.startswith(py_calibration.to_dict()["message"] + "; |a| - g rms ")


def test_full_report_has_every_estimate_with_its_std(py_calibration):
    text = py_calibration.full_report()
    assert str(py_calibration) == text
    cal = py_calibration
    assert text.splitlines()[0].endswith(cal.to_dict()["message"])
    # The accelerometer's bias and the gyroscope's, with their standard
    # deviations as the JSON holds them.
    for sensor, name in (("accel", "bias b "), ("gyro", "bias b_g ")):
        row = [l for l in text.splitlines() if l.strip().startswith(name.strip() + " ")]
        assert len(row) == 1, text
        bias = getattr(cal, sensor).bias
        std = getattr(cal, sensor).std.bias
        assert "%.6g +- %.2g" % (bias[0], std[0]) in row[0]


def test_report_of_a_calibration_read_from_json_says_why_not(tmp_path, py_calibration):
    path = tmp_path / "cal.json"
    py_calibration.to_json(path)
    loaded = gravcal.Calibration.from_json(path)
    with pytest.raises(gravcal.Error, match="no report"):
        loaded.brief_report()
    assert str(loaded) == repr(loaded)
