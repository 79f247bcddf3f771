# Bad input is fesd.InputError (a ValueError) with the fesd program's one-line message; a solver
# that does not converge is a status.
import subprocess

import pytest

import fesd

BAD = """name = "bad"
[model]
x = ["x"]
c = ["x"]
F = [[1], [3]]
x0 = [-1.0]
[simulation]
T_sim = 1
N_sim = 10
[discretization]
n_S = 2
"""


def test_a_bad_file_raises_input_error_with_the_cli_message(cli, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(BAD)
    with pytest.raises(fesd.InputError) as e:
        fesd.load(path)
    assert isinstance(e.value, ValueError)
    assert str(e.value) == f"{path}:11: unknown key 'n_S' in [discretization] (did you mean 'n_s'?)"
    p = subprocess.run([cli, "simulate", str(path)], capture_output=True, text=True)
    assert p.returncode == 2
    assert p.stderr == f"fesd: error: {e.value}\n"


def test_a_bad_override_names_the_key(examples, cli):
    with pytest.raises(fesd.InputError, match=r"unknown option 'n_S' \(did you mean 'n_s'\?\)"):
        fesd.simulate(examples / "oscillator.toml", n_S=3)
    with pytest.raises(fesd.InputError) as e:
        fesd.simulate(examples / "oscillator.toml", n_s=0)
    p = subprocess.run([cli, "simulate", str(examples / "oscillator.toml"), "--n_s", "0"],
                       capture_output=True, text=True)
    assert p.stderr == f"fesd: error: {e.value}\n"


def test_bad_dicts_and_sources():
    with pytest.raises(fesd.InputError, match="cannot be written to a problem file"):
        fesd.load({"model": {"x": [object()]}})
    with pytest.raises(fesd.InputError, match="expected a path"):
        fesd.load(42)
    with pytest.raises(fesd.InputError, match="cannot"):
        fesd.load("/nonexistent/problem.toml")


def test_the_wrong_kind_of_problem(examples):
    with pytest.raises(fesd.InputError, match="use fesd.solve"):
        fesd.simulate(examples / "ocp_sensitivity.toml")
    with pytest.raises(fesd.InputError, match="use fesd.simulate"):
        fesd.solve(examples / "oscillator.toml")


def test_non_convergence_is_a_status(examples):
    # one IPOPT iteration per NLP cannot solve the OCP: a status, not an exception
    r = fesd.solve(examples / "ocp_sensitivity.toml", ipopt={"max_iter": 1})
    assert r.status != "success" and not r.success
    assert r.message
