# The scripts in examples/python/ run as documented (from a scratch directory: they write only the
# plot they are asked for).
import importlib.util
import os
import subprocess
import sys

import pytest


def run(examples, tmp_path, script, *args):
    p = subprocess.run([sys.executable, str(examples / "python" / script), *args],
                       cwd=tmp_path, capture_output=True, text=True, timeout=300,
                       env=dict(os.environ, MPLBACKEND="Agg"))
    assert p.returncode == 0, p.stderr
    return p.stdout


def test_model_as_dict(examples, tmp_path):
    out = run(examples, tmp_path, "model_as_dict.py")
    assert "a = 2.0: success, t_s = 0.333333333333 (exact 0.333333333333)" in out
    assert "OCP: success, x0* = -1.4275722320" in out
    assert os.listdir(tmp_path) == []


def test_oscillator(examples, tmp_path):
    args = ["oscillator.png"] if importlib.util.find_spec("matplotlib") else []
    out = run(examples, tmp_path, "oscillator.py", *args)
    assert "n_s = 4: success" in out and "FESD integrator summary" in out
    assert os.listdir(tmp_path) == args


@pytest.mark.skipif(importlib.util.find_spec("distributed") is None,
                    reason="needs python3-distributed")
def test_sensitivity_sweep(examples, tmp_path):
    out = run(examples, tmp_path, "sensitivity_sweep.py")
    assert "30/30 guesses reach x0*" in out and "serial loop" in out
    assert os.listdir(tmp_path) == []
