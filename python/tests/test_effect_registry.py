"""Issue 34: an effect registered by one line in the C++ registry reaches
Python with nothing in the package naming it."""
import numpy as np

import gravcal

NEW = "accel_temperature_bias_quadratic"


def test_a_registered_effect_is_simulated_calibrated_applied_and_exported():
    truth, log = gravcal.simulate(
        seed=2, sim_scheme="random:24", sim_hold=10, sim_initial_still=5, sim_rotation_time=2,
        sim_temperature_start=20, sim_temperature_end=35, sim_temperature_tau=120,
        **{"sim_" + NEW: 3e-4})
    kappa = np.array(truth.to_dict()["effects"][NEW])
    assert np.abs(kappa).max() > 0
    before = gravcal._gravcal._json_conversions()
    cal = gravcal.calibrate(log, effects=["accel_temperature_bias", NEW])
    accel = cal.apply(log.accel, temp=log.temp, t=log.t)
    exported = gravcal.export(cal, "c", name="unit")
    assert gravcal._gravcal._json_conversions() == before
    assert accel.shape == log.accel.shape and np.isfinite(accel).all()
    # The C corrector writes its term from its definition: nothing dropped.
    assert not exported["dropped"]
    assert any("D_ACCEL_TEMPERATURE_BIAS_QUADRATIC" in f["text"] for f in exported["files"])
    estimate = cal.to_dict()["effects"][NEW]
    assert estimate["parameters"] == ["kappa_x", "kappa_y", "kappa_z"]
    value, std = np.array(estimate["value"]), np.array(estimate["std"])
    assert (np.abs(value - kappa) < 4 * std).all(), (value, kappa, std)
