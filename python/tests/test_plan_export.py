"""plan, check and export from Python equal `gravcal plan`, `gravcal check`,
`gravcal export` on the same input; simulate(plan=) equals
`gravcal simulate --plan` (issue 18)."""
import pytest

import gravcal
from conftest import config_path, read_json, run_cli, strip_times

TWELVE = config_path("twelve_position.yaml")
TARGET = "accel_bias=0.5mg accel_scale=100ppm"
DENSITY = "0.002"
# Every other request flag, away from its default, so that a keyword mapped
# to the wrong field shows.
PLAN_KEYWORDS = {"overhead": 7.0, "min_hold": 4.0, "max_hold": 500.0, "max_time": 1000.0,
                 "accel_bias_instability": 1e-4, "pose_disturbance": 1e-4}
PLAN_FLAGS = [x for k, v in PLAN_KEYWORDS.items() for x in ("--" + k, repr(v))]


@pytest.fixture(scope="module")
def cli_plan(tmp_path_factory):
    out = tmp_path_factory.mktemp("plan") / "plan.json"
    run_cli("plan", "--config", TWELVE, "--target", TARGET, "--accel_noise_density", DENSITY,
            "--pose_set", "faces+45", *PLAN_FLAGS, "--output", out)
    return out


def test_plan_equals_cli(cli_plan, tmp_path):
    out = tmp_path / "py_plan.json"
    result = gravcal.plan(TWELVE, target=TARGET, accel_noise_density=float(DENSITY),
                          pose_set="faces+45", output=out, **PLAN_KEYWORDS)
    assert out.read_bytes() == cli_plan.read_bytes()
    assert result == read_json(cli_plan)
    assert result["poses"] and result["meets_targets"]


def test_plan_error_is_the_cli_message(tmp_path):
    # A writable output: the CLI checks its destinations before the work.
    _, error = run_cli("plan", "--config", TWELVE, "--target", TARGET, "--output",
                       tmp_path / "plan.json", ok=False)
    assert error and not (tmp_path / "plan.json").exists()
    with pytest.raises(gravcal.Error) as e:
        gravcal.plan(TWELVE, target=TARGET)
    assert str(e.value) == error


def test_simulate_with_a_plan_equals_cli(cli_plan, tmp_path):
    run_cli("simulate", "--config", TWELVE, "--plan", cli_plan, "--seed", 3, "--output-dir",
            tmp_path)
    truth, log, files = gravcal.simulate(TWELVE, 3, plan=cli_plan, return_files=True)
    assert truth == read_json(tmp_path / "truth.json")
    log.to_csv(tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "raw.csv").read_bytes()
    assert files["attitudes.csv"] == (tmp_path / "attitudes.csv").read_text()


def test_check_equals_cli(tmp_path):
    run_cli("simulate", "--config", TWELVE, "--sim_scheme", "six", "--seed", 5, "--output-dir",
            tmp_path)
    raw = tmp_path / "raw.csv"
    printed = run_cli("check", "--config", TWELVE, "--input", raw, "--target", TARGET,
                      stdout=True)
    report = gravcal.check(raw, config=TWELVE, target=TARGET)
    assert report["text"] == printed
    assert report["positions"] == 6
    assert set(report["undetermined"]) == {"u_xy", "u_xz", "u_yz"}
    assert len(report["proposed"]) == 3 and report["undetermined_with_proposed"] == []


@pytest.fixture(scope="module")
def still_noise(tmp_path_factory):
    """`gravcal noise` of a simulated log in SI units with a 1200 s still
    start and bias random walks strong enough to show (Kalibr needs K)."""
    d = tmp_path_factory.mktemp("noise")
    run_cli("simulate", "--sim_raw_counts", "false", "--sim_scheme", "six",
            "--sim_initial_still", 1200, "--sim_hold", 5, "--sim_accel_bias_random_walk", "1e-3",
            "--sim_gyro_bias_random_walk", "1e-4", "--seed", 4, "--output-dir", d)
    run_cli("noise", "--input", d / "raw.csv", "--output", d / "noise.json")
    return d / "noise.json"


@pytest.fixture(scope="module")
def si_calibration(tmp_path_factory):
    """A twelve-position calibration with gyroscope of a log in m/s^2 and
    rad/s (the firmware targets need SI raw units)."""
    d = tmp_path_factory.mktemp("si")
    cfg = config_path("twelve_position_gyro.yaml")
    run_cli("simulate", "--config", cfg, "--sim_raw_counts", "false", "--seed", 5,
            "--output-dir", d)
    run_cli("calibrate", "--config", cfg, "--input", d / "raw.csv", "--output", d / "cal.json")
    return str(d / "cal.json")


def test_noise_of_the_si_log_equals_cli(still_noise):
    result = gravcal.noise(still_noise.parent / "raw.csv")
    assert strip_times(result) == strip_times(read_json(still_noise))


def test_plan_with_a_noise_dict_equals_the_file(still_noise):
    from_file = gravcal.plan(TWELVE, target=TARGET, pose_set="faces+45", noise=still_noise)
    from_dict = gravcal.plan(TWELVE, target=TARGET, pose_set="faces+45",
                             noise=read_json(still_noise))
    assert from_file == from_dict


@pytest.mark.parametrize("target", ["kalibr", "openvins", "ros", "px4", "ardupilot", "c"])
def test_export_equals_cli(target, si_calibration, still_noise, tmp_path):
    args = ["export", "--calibration", si_calibration, "--to", target,
            "--noise", still_noise]
    if target == "c":
        args += ["--output-dir", tmp_path]
    else:
        args += ["--output", tmp_path / "out"]
    run_cli(*args)
    result = gravcal.export(si_calibration, target, noise=still_noise)
    names = [f["name"] or "out" for f in result["files"]]
    written = [p.name for p in tmp_path.iterdir()] if target == "c" else ["out"]
    assert sorted(names) == sorted(written)
    for f in result["files"]:
        path = tmp_path / (f["name"] or "out")
        assert f["text"] == path.read_text(), target
    # The same from a Calibration and the noise as a dict.
    again = gravcal.export(gravcal.Calibration.from_json(si_calibration), target,
                           noise=read_json(still_noise))
    assert again["files"] == result["files"]
    assert (result["dropped"] == []) == (target not in ("px4", "ardupilot"))


def test_export_errors_are_the_cli_messages(cli_calibration, tmp_path):
    _, error = run_cli("export", "--calibration", cli_calibration, "--to", "kalibr", "--output",
                       tmp_path / "imu.yaml", ok=False)
    assert error and not (tmp_path / "imu.yaml").exists()
    with pytest.raises(gravcal.Error) as e:
        gravcal.export(str(cli_calibration), "kalibr")
    assert str(e.value) == error
    with pytest.raises(gravcal.Error, match=r"^key 'to': 'matlab' is not one of kalibr, .* or c$"):
        gravcal.export(str(cli_calibration), "matlab")


def test_results_read_as_attributes_and_stay_dicts(cli_plan, still_noise):
    plan = gravcal.plan(TWELVE, target=TARGET, pose_set="faces+45",
                        accel_noise_density=float(DENSITY), **PLAN_KEYWORDS)
    assert isinstance(plan, dict) and isinstance(plan, gravcal.Result)
    assert plan.poses[0]["up"] == plan["poses"][0]["up"]
    assert plan.predicted_std.bias_x == plan["predicted_std"]["bias_x"]
    assert type(plan.to_dict()) is dict and plan.to_dict() == read_json(cli_plan)
    noise = gravcal.noise(still_noise.parent / "raw.csv")
    assert noise.accel.x.white_noise.value == noise["accel"]["x"]["white_noise"]["value"]
    with pytest.raises(AttributeError, match="no key 'nonsense'"):
        noise.nonsense
