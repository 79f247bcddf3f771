# fesd.batch.map on a 2-worker local Dask cluster (skipped without python3-distributed): results
# in order, the same numbers as serial runs, a failing case does not stop the others, nothing is
# written into the working directory, Dask's scratch space is removed.
import os
import tempfile

import numpy as np
import pytest

import fesd

pytest.importorskip("distributed")
import fesd.batch  # noqa: E402


def test_a_sweep_on_a_local_cluster(examples, tmp_path, monkeypatch, capsys):
    work, temp = tmp_path / "work", tmp_path / "temp"
    work.mkdir()
    temp.mkdir()
    monkeypatch.chdir(work)
    monkeypatch.setattr(tempfile, "tempdir", str(temp))  # where Dask's scratch space goes
    cases = [{"n_s": 1}, {"n_s": 2}, {"n_s": 0}, {"n_s": 3, "N_sim": 40},
             {"x0": [0.5, 0.0], "error_estimate": False}]
    path = examples / "oscillator.toml"
    results = fesd.batch.map(path, overrides=cases, n_workers=2)
    assert len(results) == len(cases)
    for case, r in zip(cases, results):
        if case.get("n_s") == 0:  # out of range: this case fails, the others run
            assert isinstance(r, fesd.batch.CaseError)
            assert r.status == "input_error" and not r.success
            assert r.message == "--n_s = 0: must be in 1..9 for radau_iia"
            assert r.overrides == case
            continue
        assert isinstance(r, fesd.SimulationResult) and r.status == "success"
        serial = fesd.simulate(path, **case)
        np.testing.assert_array_equal(r.x, serial.x)
        np.testing.assert_array_equal(r.switch_times, serial.switch_times)
    assert results[3].x.shape == (81, 2)
    assert "5/5" in capsys.readouterr().err  # the progress bar
    assert os.listdir(work) == []
    assert os.listdir(temp) == []  # the scratch space was there and is removed


def test_ocp_sweep_and_bad_input(examples):
    problem = {
        "model": {"x": ["x"], "c": ["x"], "F": [[1], [3]], "x0": [-2.0]},
        "ocp": {"T": 2.0, "f_q": "x^2", "f_q_T": "(x - 5/3)^2", "lbx0": [-np.inf],
                "ubx0": [np.inf], "initialization": "simulation"},
        "discretization": {"rk_scheme": "gauss_legendre", "n_s": 2, "N_finite_elements": 25},
        "homotopy": {"mpcc_mode": "scholtes_eq", "sigma_N": 1e-15, "complementarity_tol": 1e-12},
    }
    guesses = [-3.0, 1.0]
    results = fesd.batch.map(problem, [{"x0": [g]} for g in guesses], n_workers=2,
                             progress=False)
    x0_star = (9 - np.sqrt(417)) / 8
    for r in results:
        assert r.status == "success" and abs(r.x0[0] - x0_star) < 1e-6
    with pytest.raises(fesd.InputError, match="unknown key"):  # checked before any worker starts
        fesd.batch.map({"model": {"xx": 1}}, [{}])
    # a Problem with overrides travels as its text and overrides
    p = fesd.with_options(examples / "oscillator.toml", n_s=2, N_sim=10, error_estimate=False)
    [r] = fesd.batch.map(p, [{}], n_workers=1, progress=False)
    np.testing.assert_array_equal(r.x, fesd.simulate(p).x)
    assert r.t_stage.shape == (40,)  # 10 steps x 2 elements x 2 stages
