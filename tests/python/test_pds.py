# Projected dynamical systems from Python (docs/pds.md, docs/python.md): Example 1 of fesd-pds.txt
# read from its file and from a dict, against the exact solution (REFERENCE.md): contact at
# t = 5 pi / 12, leaving at 5 pi / 12 + sqrt 3, x(T) = (-1, 0).
import math
import pickle

import numpy as np
import pytest

import fesd

T_CONTACT = 5 * math.pi / 12
T_LEAVE = T_CONTACT + math.sqrt(3)


def check_example1(r):
    # Radau IIA n_s = 3, one step of 20 elements (the file): error 1.5e-7 measured; bound 1e-5.
    assert r.success, r.message
    assert r.projected
    assert np.linalg.norm(r.x[-1] - [-1, 0]) < 1e-5
    assert r.switch_times == pytest.approx([T_CONTACT, T_LEAVE], abs=1e-5)
    assert r.lambda_.shape == (r.t_stage.size, 1)  # one multiplier per constraint
    assert r.theta.shape[1] == 0 and r.mu.shape[1] == 0
    in_contact = np.abs(r.x[:, 1] + 1) < 1e-6  # on x2 = -1 between contact and leaving
    assert np.all(in_contact[(r.t > T_CONTACT + 1e-3) & (r.t < T_LEAVE - 1e-3)])


def test_example1_from_its_file(examples):
    p = fesd.load(examples / "pds_example1.toml")
    assert p.projected and p.kind == "simulation"
    assert p.n_constraints == 1 and p.n_regions == 0
    assert p.state_names == ["x1", "x2"]
    check_example1(fesd.simulate(p))
    q = pickle.loads(pickle.dumps(p))
    assert q.projected and q.n_constraints == 1


def test_example1_from_a_dict():
    d = {"name": "pds1",
         "model": {"kind": "projected", "x": ["x1", "x2"], "f": ["x2", "-x1"],
                   "constraints": ["x2 + 1"], "x0": [math.sqrt(2), math.sqrt(2)]},
         "simulation": {"T_sim": 11 * math.pi / 12 + math.sqrt(3), "N_sim": 1},
         "discretization": {"rk_scheme": "radau_iia", "n_s": 3, "N_finite_elements": 20}}
    check_example1(fesd.simulate(d))


def test_projected_input_errors(examples):
    with pytest.raises(fesd.InputError, match="tol_sim"):
        fesd.simulate(examples / "pds_example1.toml", tol_sim=-1)
    with pytest.raises(fesd.InputError, match="x0 lies outside C"):  # x0 below x2 = -1
        fesd.simulate({"model": {"kind": "projected", "x": ["x1", "x2"], "f": ["x2", "-x1"],
                             "constraints": ["x2 + 1"], "x0": [0, -2]},
                   "simulation": {"T_sim": 1, "N_sim": 1}})


def test_projected_plot_draws_the_boundary_and_contact(examples):
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    fig = fesd.simulate(examples / "pds_example1.toml").plot()
    lines = {line.get_label(): np.asarray(line.get_xydata()) for line in fig.axes[-1].lines}
    boundary = lines["c[0] = 0"]
    assert np.nanmax(np.abs(boundary[:, 1] + 1)) < 1e-9  # the line x2 = -1
    contact = lines["contact"]
    assert np.max(np.abs(contact[:, 1] + 1)) < 1e-6
    assert contact[:, 0].min() == pytest.approx(0, abs=1e-5)  # leaves at (0, -1)
    matplotlib.pyplot.close(fig)


def test_projected_overrides(examples):
    # Radau IIA n_s = 2 instead of the file's 3 (20 elements): error 3.9e-4 measured (docs/pds.md).
    r = fesd.simulate(examples / "pds_example1.toml", n_s=2)
    assert r.success, r.message
    assert 1e-5 < np.linalg.norm(r.x[-1] - [-1, 0]) < 1e-3


def test_projected_tol_sim_and_t0(examples):
    # tol_sim as for piecewise smooth files (runs N_sim = 1, 2, 4 measured, error 2.4e-10);
    # t0 = 5 offsets every time and leaves x(T) as it is.
    r = fesd.simulate(examples / "pds_example1.toml", tol_sim=1e-6, t0=5)
    assert r.success, r.message
    assert np.linalg.norm(r.x[-1] - [-1, 0]) <= 1e-6
    assert r.t[0] == 5
    assert r.switch_times == pytest.approx([5 + T_CONTACT, 5 + T_LEAVE], abs=1e-5)
