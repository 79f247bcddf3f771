# fesd.simulate from Python: the oscillator (47) against its exact solution
# (/work/shared/REFERENCE.md), overrides by keyword, a problem from a dict, pickling.
import json
import math
import pickle
import subprocess

import numpy as np

import fesd

# x(T) of the oscillator (47) as printed, T = pi/2; the switch is at t_s = 1.
X_EXACT = np.array([-1.5974603774506984, -0.7614936206060108])


def test_oscillator_file_matches_the_exact_solution(examples):
    r = fesd.simulate(examples / "oscillator.toml")
    assert r.status == "success" and r.success
    assert r.message
    assert r.name == "oscillator"
    assert r.state_names == ["x1", "x2"]
    assert np.linalg.norm(r.x[-1] - X_EXACT) < 1e-7
    np.testing.assert_array_equal(r.x_final, r.x[-1])
    assert r.t[0] == 0 and abs(r.t[-1] - math.pi / 2) < 1e-12
    assert r.switch_times.shape == (1,)
    assert abs(r.switch_times[0] - 1.0) < 1e-6
    s = r.switches[0]
    assert s["before"] == [0] and s["after"] == [1] and s["located"]
    assert s["t"] == r.switch_times[0]
    # 100 steps of 2 elements, Radau IIA with 3 stages, 2 regions, 1 subsystem
    assert r.x.shape == (201, 2) and r.h.shape == (200,) and r.t.shape == (201,)
    assert abs(r.h.sum() - math.pi / 2) < 1e-12
    assert r.t_stage.shape == (600,) and r.x_stage.shape == (600, 2)
    assert r.theta.shape == (600, 2) and r.lambda_.shape == (600, 2) and r.mu.shape == (600, 1)
    assert len(r.active_set) == 200 and r.active_set[0] == [0] and r.active_set[-1] == [1]
    assert np.all(r.theta >= -1e-9) and np.all(np.abs(r.theta.sum(axis=1) - 1) < 1e-9)
    assert r.summary["wall_s"] > 0 and r.summary["warnings"] == []
    assert r.summary["active_set_path_steps"] + r.summary["homotopy_path_steps"] == 100
    assert r.accuracy["N_sim"] == 100 and r.accuracy["error_estimate"] < 1e-6
    assert len(r.homotopy) >= 1


def test_the_reports_are_the_cli_reports(examples):
    r = fesd.simulate(examples / "oscillator.toml", N_sim=20)
    assert r.brief_report().startswith("success: x(1.5708) = [")
    assert "FESD integrator summary" in r.full_report()
    assert "t_s = 1" in r.full_report()
    assert r.brief_report().strip() in repr(r)


def test_same_numbers_as_the_fesd_program(examples, cli, tmp_path):
    out = tmp_path / "oscillator.json"
    subprocess.run([cli, "simulate", str(examples / "oscillator.toml"), "--n_s", "2",
                    "--N_sim", "30", "--json", str(out)], check=True, capture_output=True)
    data = json.loads(out.read_text())
    r = fesd.simulate(examples / "oscillator.toml", n_s=2, N_sim=30)
    np.testing.assert_allclose(r.x, np.array(data["x"]), rtol=0, atol=1e-14)
    np.testing.assert_allclose(r.t, np.array(data["t"]), rtol=0, atol=1e-14)


def test_overrides_by_keyword(examples):
    r = fesd.simulate(str(examples / "oscillator.toml"), n_s=2, N_sim=40,
                      rk_scheme="gauss_legendre", error_estimate=False)
    assert r.status == "success"
    assert r.x.shape == (81, 2) and r.t_stage.shape == (160,)  # 40 steps x 2 elements x 2 stages
    assert 1e-6 < np.linalg.norm(r.x[-1] - X_EXACT) < 1e-4  # 3.3e-5: Gauss-Legendre, 2 stages
    assert abs(r.switch_times[0] - 1.0) < 1e-5
    assert len(r.accuracy["runs"]) == 1  # no companion runs
    # parameters by name, x0 as a list, IPOPT options as a dict, dotted keys through `options`
    r = fesd.simulate(examples / "oscillator.toml", N_sim=10, p={"omega": 2 * math.pi},
                      x0=np.array([math.exp(-1), 0.0]), ipopt={"tol": 1e-12},
                      options={"discretization.N_FE": 3})
    assert r.status == "success" and r.x.shape == (31, 2)
    assert np.linalg.norm(r.x[-1] - X_EXACT) < 1e-4


def test_with_options_returns_a_modified_copy(examples):
    p = fesd.load(examples / "oscillator.toml")
    q = fesd.with_options(p, x0=[0.5, 0.0], p={"omega": 3.0})
    assert list(q.x0) == [0.5, 0.0] and q.parameters == {"omega": 3.0}
    assert list(p.x0) == [math.exp(-1), 0.0]
    assert p.kind == "simulation" and p.name == "oscillator" and p.n_regions == 2


def example3(T_sim=1.0):
    """Example 3 of the paper, x' in 2 - sign(x), x(0) = -1, as a dict."""
    return {
        "name": "example3",
        "model": {"x": ["x"], "c": ["x"], "F": [[1], [3]], "x0": [-1.0]},
        "simulation": {"T_sim": T_sim, "N_sim": 6},
        "discretization": {"rk_scheme": "radau_iia", "n_s": 2, "N_finite_elements": 3},
    }


def test_a_problem_from_a_dict():
    r = fesd.simulate(example3())
    assert r.status == "success" and r.name == "example3"
    assert abs(r.x[-1][0] - (1 - 1 / 3)) < 1e-9  # x(T) = T - 1/3
    assert abs(r.switch_times[0] - 1 / 3) < 1e-9
    # the same from keyword tables, with a parameter and an inline table
    d = example3()
    r2 = fesd.simulate(fesd.load(None, name="kw", model=dict(d["model"], F=[["a"], ["a + 2"]],
                                                             p={"a": 1.0}),
                                 simulation=d["simulation"], discretization=d["discretization"]))
    np.testing.assert_allclose(r2.x, r.x, rtol=0, atol=1e-12)
    assert "[model]" in fesd.to_toml(d) and 'x = ["x"]' in fesd.to_toml(d)


def test_results_pickle(examples):
    r = fesd.simulate(examples / "oscillator.toml", N_sim=20)
    r2 = pickle.loads(pickle.dumps(r))
    assert type(r2) is fesd.SimulationResult
    np.testing.assert_array_equal(r2.x, r.x)
    np.testing.assert_array_equal(r2.lambda_, r.lambda_)
    assert r2.switches == r.switches and r2.summary == r.summary
    assert r2.brief_report() == r.brief_report() and r2.full_report() == r.full_report()


def test_problems_pickle(examples):
    p = fesd.with_options(examples / "oscillator.toml", n_s=2, p={"omega": 3.0})
    q = pickle.loads(pickle.dumps(p))
    assert q.name == "oscillator" and q.parameters == {"omega": 3.0}
    np.testing.assert_array_equal(fesd.simulate(q, N_sim=10).x, fesd.simulate(p, N_sim=10).x)
    d = pickle.loads(pickle.dumps(fesd.load(example3(), name="ex3")))
    assert d.name == "example3" and d.source == "ex3"


def test_sensitivities_of_example_3a(examples):
    # Example 3(a), x' in 2 - sign(x), x0 = -1 (examples/crossing.toml): dx(T)/dx0 = 1/3
    # (docs/sensitivities.md); the model has no controls or parameters.
    r = fesd.simulate(examples / "crossing.toml", sensitivities=True, error_estimate=False)
    s = r.sensitivities
    assert s["requested"] and s["available"], s["message"]
    assert s["x0"].shape == (1, 1)
    assert abs(s["x0"][0, 0] - 1.0 / 3.0) < 1e-12
    assert s["u"].shape == (1, 0) and s["p"].shape == (1, 0)
    assert not fesd.simulate(examples / "crossing.toml").sensitivities["requested"]
    assert r.step_path == ["active_set"] * 10
