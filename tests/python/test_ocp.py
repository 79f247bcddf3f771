# fesd.solve from Python: the sensitivity OCP (56) reaches its exact minimizer (as
# tests/io/ocp_problem_file_test.cpp asserts for the C++ solve of the same file).
import math
import pickle

import numpy as np

import fesd

X0_STAR = (9 - math.sqrt(417)) / 8  # -1.4275722320827671
V_STAR = 1.5237727753749571


def test_sensitivity_ocp(examples):
    r = fesd.solve(examples / "ocp_sensitivity.toml")
    assert r.status == "success", r.message
    assert abs(r.objective - V_STAR) < 1e-6
    assert abs(r.x0[0] - X0_STAR) < 1e-6
    np.testing.assert_array_equal(r.x0, r.x[0])
    assert abs(r.switch_times[0] - (-X0_STAR / 3)) < 1e-5  # crosses x = 0 at -x0*/3
    assert r.t_ctrl.shape == (2,) and r.u.shape == (1, 0)  # one stage, no controls
    assert r.x.shape == (26, 1) and r.h.shape == (25,) and len(r.interval) == 25
    assert r.eta.shape == (25,) and math.isnan(r.eta[0])
    assert r.mpcc_mode == "scholtes_eq"
    assert r.homotopy and r.homotopy[-1]["nlp_status"]
    assert r.summary["homotopy_steps"] == len(r.homotopy)
    assert "objective" in r.brief_report()
    r2 = pickle.loads(pickle.dumps(r))
    assert r2.objective == r.objective and r2.full_report() == r.full_report()


def test_ocp_overrides_and_dict(examples):
    p = fesd.load(examples / "ocp_sensitivity.toml")
    assert p.kind == "ocp"
    d = {
        "name": "sens",
        "model": {"x": ["x"], "c": ["x"], "F": [[1], [3]], "x0": [0.5]},
        "ocp": {"T": 2.0, "N_stages": 1, "f_q": "x^2", "f_q_T": "(x - 5/3)^2",
                "lbx0": [-math.inf], "ubx0": [math.inf], "initialization": "simulation"},
        "discretization": {"rk_scheme": "gauss_legendre", "n_s": 2, "N_finite_elements": 25},
        "homotopy": {"mpcc_mode": "scholtes_eq", "sigma_N": 1e-15,
                     "complementarity_tol": 1e-12},
    }
    r = fesd.solve(d, N_FE=20)
    assert r.status == "success", r.message
    assert r.x.shape == (21, 1)
    assert abs(r.x0[0] - X0_STAR) < 1e-5
