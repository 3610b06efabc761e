"""compare, verify, history, limits and the certificate from Python equal
the CLI's on the same input (issue 36), and the test-station example runs."""
import importlib.util
import json
import os

import pytest

import gravcal
from conftest import SOURCE_DIR, config_path, read_json, run_cli

TWELVE = config_path("twelve_position.yaml")


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    """Two simulated sessions of different units, calibrated by the CLI."""
    d = tmp_path_factory.mktemp("verify")
    for seed in (1, 2):
        run_cli("simulate", "--config", TWELVE, "--seed", seed, "--output-dir", d / ("s%d" % seed))
        run_cli("calibrate", "--config", TWELVE, "--input", d / ("s%d/raw.csv" % seed),
                "--output", d / ("c%d.json" % seed))
    return d


def test_compare_equals_cli(session, tmp_path):
    run_cli("compare", session / "c1.json", session / "c1.json", "--output", tmp_path / "same.json")
    same = gravcal.compare(session / "c1.json", session / "c1.json", output=tmp_path / "py.json")
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "same.json").read_bytes()
    assert same.consistent and same == read_json(tmp_path / "same.json")
    # Two different units: changed, the CLI exits 3 with the same result.
    code, _ = run_cli("compare", session / "c1.json", session / "c2.json", "--output",
                      tmp_path / "diff.json", ok=False)
    diff = gravcal.compare(gravcal.Calibration.from_json(session / "c1.json"),
                           session / "c2.json")
    assert code == 3 and not diff.consistent
    assert diff == read_json(tmp_path / "diff.json")
    intrinsic = gravcal.compare(session / "c1.json", session / "c1.json", space="intrinsic")
    assert intrinsic.parameters[0].name.startswith("accel.")
    with pytest.raises(gravcal.Error, match="space"):
        gravcal.compare(session / "c1.json", session / "c1.json", space="nowhere")
    with pytest.raises(gravcal.Error, match="level"):
        gravcal.compare(session / "c1.json", session / "c1.json", level=2)


def test_verify_equals_cli(session, tmp_path):
    run_cli("verify", "--calibration", session / "c1.json", "--input", session / "s1/raw.csv",
            "--config", TWELVE, "--output", tmp_path / "v.json")
    result = gravcal.verify(session / "c1.json", str(session / "s1/raw.csv"), config=TWELVE)
    assert result == read_json(tmp_path / "v.json")
    assert result.consistent
    # The other unit's session against this calibration: changed.
    other = gravcal.verify(session / "c1.json", str(session / "s2/raw.csv"), config=TWELVE)
    assert not other.consistent and other.changed


def test_store_history_and_closest(session, tmp_path):
    store = tmp_path / "store"
    gravcal.file_calibration(store, "SN1", session / "c1.json", date="2026-01-01T00:00:00Z")
    gravcal.file_calibration(store, "SN1", session / "c1.json", date="2026-03-01T00:00:00Z")
    run_cli("history", "SN1", "--store", store, "--output", tmp_path / "h.json")
    history = gravcal.history("SN1", store)
    assert history == read_json(tmp_path / "h.json")
    assert len(history.calibrations) == 2
    cal, entry = gravcal.closest_calibration(store, "SN1", date="2026-01-20T00:00:00Z")
    assert entry.date == "2026-01-01T00:00:00Z" and not entry.warning
    assert cal.to_json() == (session / "c1.json").read_text()
    with pytest.warns(UserWarning, match="recalibrate"):
        gravcal.closest_calibration(store, "SN1", date="2026-12-01T00:00:00Z", max_age_days=30)
    with pytest.raises(gravcal.Error, match="no calibration of unit 'SN2'"):
        gravcal.closest_calibration(store, "SN2")


def test_limits_and_certificate(session, tmp_path):
    limits = {"parameters": {"accel.bias_z": {"max_std": 1e-9}}, "residual_rms": 0.01,
              "accel_noise_density": 0.003}
    result = gravcal.check_limits(session / "c1.json", limits)
    assert result.verdict == "fail"
    failed = [c.name for c in result.limits if not c["pass"]]
    assert failed == ["accel.bias_z std"]
    (tmp_path / "limits.yaml").write_text(json.dumps(limits))
    assert gravcal.check_limits(session / "c1.json", tmp_path / "limits.yaml") == result
    with pytest.raises(gravcal.Error, match="accel_noise_density"):
        gravcal.check_limits(session / "c1.json", {"accel_noise_density": -1})
    # No gyroscope model and no gyro_nominal_scale: the gyroscope's unit is
    # unknown, so a gyroscope noise limit fails as not measured, said why.
    gyro = gravcal.check_limits(session / "c1.json", {"gyro_noise_density": {"max": 1e-3}})
    assert gyro.verdict == "fail" and "gyro_nominal_scale" in gyro.limits[0].why
    with pytest.raises(gravcal.Error, match="gyro_noise_density.typical"):
        gravcal.check_limits(session / "c1.json", {"gyro_noise_density": {"typical": 1e-3}})
    cert, html = gravcal.certificate(session / "c1.json", limits=limits, unit="SN1",
                                     station="line-3", output=tmp_path / "cert")
    assert cert.unit == "SN1" and cert.station == "line-3" and cert.verdict == "fail"
    assert (tmp_path / "cert.html").read_text() == html and "FAIL" in html
    assert read_json(tmp_path / "cert.json") == cert
    for p in cert.parameters:
        if p.standard_uncertainty is not None:
            total = sum(b.standard_uncertainty ** 2 for b in p.budget) ** 0.5
            assert total == pytest.approx(p.standard_uncertainty, rel=1e-12)


def _station():
    path = os.path.join(SOURCE_DIR, "examples", "test_station.py")
    spec = importlib.util.spec_from_file_location("test_station", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_station_example(session, tmp_path):
    station = _station()
    (tmp_path / "pass.yaml").write_text("residual_rms: 0.01\naccel_noise_density: 0.003\n")
    (tmp_path / "fail.yaml").write_text("residual_rms: 0.01\naccel_noise_density: 0.001\n")
    assert station.main([str(session / "s1/raw.csv"), "--unit", "SN1", "--limits",
                         str(tmp_path / "pass.yaml"), "--config", TWELVE, "--out",
                         str(tmp_path / "out")]) == 0
    record = read_json(tmp_path / "out/SN1.record.json")
    assert record["outcome"] == "PASS"
    assert set(record["measurements"]) == {"residual_rms", "accel_noise_density"}
    assert read_json(tmp_path / "out/SN1.certificate.json")["verdict"] == "pass"
    assert station.main([str(session / "s1/raw.csv"), "--unit", "SN2", "--limits",
                         str(tmp_path / "fail.yaml"), "--config", TWELVE, "--out",
                         str(tmp_path / "out")]) == 1
    record = read_json(tmp_path / "out/SN2.record.json")
    assert record["measurements"]["accel_noise_density"]["outcome"] == "FAIL"
    assert record["measurements"]["residual_rms"]["outcome"] == "PASS"


def test_station_as_openhtf_test(session, tmp_path):
    pytest.importorskip("openhtf")
    station = _station()
    (tmp_path / "pass.yaml").write_text("residual_rms: 0.01\n")
    (tmp_path / "fail.yaml").write_text("residual_rms: 0.01\naccel_noise_density: 0.001\n")
    records = []
    for limits, passes in (("pass.yaml", True), ("fail.yaml", False)):
        test = station.openhtf_test("SN1", {"log": str(session / "s1/raw.csv"), "config": TWELVE,
                                            "limits": str(tmp_path / limits)})
        test.add_output_callbacks(records.append)
        assert test.execute(test_start=lambda: "SN1") == passes
    # The record: the verdict and each limit measured, the certificate attached.
    for record, verdict in zip(records, ("pass", "fail")):
        phase = [p for p in record.phases if p.name == "station_phase"][0]
        assert phase.measurements["verdict"].measured_value.value == verdict
        limits = dict(phase.measurements["limit_value"].measured_value.value)
        assert "residual_rms" in limits
        assert ("accel_noise_density" in limits) == (verdict == "fail")
        assert any(name.endswith("certificate.json") for name in phase.attachments)
