# result.plot(): the panels of the fesd program's --plot pictures, drawn with matplotlib (skipped
# without python3-matplotlib).
import numpy as np
import pytest

import fesd

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")


def test_simulation_plot(examples, tmp_path):
    r = fesd.simulate(examples / "oscillator.toml", N_sim=20)
    path = tmp_path / "oscillator.png"
    fig = r.plot(path)
    assert path.stat().st_size > 10000
    states, steps, portrait = fig.axes  # states, h_n, phase portrait (two states)
    assert [line.get_label() for line in states.lines[:2]] == ["x1", "x2"]
    assert any(t.get_text() == "{0}->{1}" for t in states.texts)  # the switch, labelled
    assert steps.get_ylabel().startswith("h_n")
    assert portrait.get_xlabel() == "x1" and portrait.get_ylabel() == "x2"
    matplotlib.pyplot.close(fig)


def test_ocp_plot(examples, tmp_path):
    r = fesd.solve(examples / "ocp_sensitivity.toml")
    fig = r.plot(tmp_path / "sensitivity.svg", title="OCP (56)")
    assert (tmp_path / "sensitivity.svg").exists()
    assert [ax.get_ylabel() for ax in fig.axes][::2] == ["x", "eta_n"]  # no controls: x, h, eta
    assert len(fig.axes) == 3 and fig.axes[2].get_yscale() == "log"
    assert fig._suptitle.get_text() == "OCP (56)"
    matplotlib.pyplot.close(fig)


def test_phase_portrait_draws_the_switching_surface_and_sliding(examples):
    # The oscillator's surface c = x1^2 + x2^2 - 1 = 0: every drawn point on the unit circle, to
    # the marching squares' accuracy on the 161 x 161 grid (linear interpolation along an edge of
    # length < 0.03: the radius is off by less than 1e-3).
    r = fesd.simulate(examples / "oscillator.toml", N_sim=20, error_estimate=False)
    fig = r.plot()
    portrait = fig.axes[-1]
    (circle,) = [line for line in portrait.lines if line.get_label() == "c[0] = 0"]
    xy = np.asarray(circle.get_xydata())
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    assert len(xy) > 100
    assert np.max(np.abs(np.hypot(xy[:, 0], xy[:, 1]) - 1)) < 1e-3
    matplotlib.pyplot.close(fig)

    # Two subsystems (docs/problem-files.md): x1 reaches 0 at t = 1 and slides; the surfaces are
    # x1 = 0 (c-form) and x2 = 0 (g-form, g[0] = g[1]); the sliding part of the trajectory is
    # drawn on x1 = 0 from x2 = -1 to 0.
    d = {"name": "two", "model": {"x": ["x1", "x2"], "x0": [1, -2], "subsystem": [
        {"c": ["x1"], "F": [["-1", "0"], ["1", "0"]]},
        {"g": ["-x2", "x2"], "F": [["0", "-1"], ["0", "1"]]}]},
        "simulation": {"T_sim": 3, "N_sim": 12}}
    fig = fesd.simulate(d).plot()
    lines = {line.get_label(): np.asarray(line.get_xydata()) for line in fig.axes[-1].lines}
    x1_zero, x2_zero = lines["c[0] = 0 (subsys. 0)"], lines["g[0] = g[1] (subsys. 1)"]
    assert np.nanmax(np.abs(x1_zero[:, 0])) < 1e-12 and np.nanmax(np.abs(x2_zero[:, 1])) < 1e-12
    sliding = lines["sliding"]
    assert np.max(np.abs(sliding[:, 0])) < 1e-9
    assert np.min(sliding[:, 1]) == pytest.approx(-1, abs=1e-9)
    assert np.max(sliding[:, 1]) == pytest.approx(0, abs=1e-9)
    matplotlib.pyplot.close(fig)
