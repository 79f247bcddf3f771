# result.plot(): the panels of the fesd program's --plot pictures, drawn with matplotlib (skipped
# without python3-matplotlib).
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
