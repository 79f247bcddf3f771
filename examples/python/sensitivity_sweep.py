"""The sensitivity OCP (56) from 30 initial guesses of x0 over [-3, 3], on a local Dask cluster:
FESD reaches the exact minimizer x0* = (9 - sqrt(417)) / 8 from every guess (Fig. 9 right of the
FESD paper). Prints the wall time against a serial loop and, with a file name, plots x0* over the
guess:

    PYTHONPATH=build/python python3 examples/python/sensitivity_sweep.py [sweep.png]
"""
import math
import os
import sys
import time

import numpy as np

import fesd
import fesd.batch

HERE = os.path.dirname(os.path.abspath(__file__))
PROBLEM = os.path.join(HERE, "..", "ocp_sensitivity.toml")
X0_STAR = (9 - math.sqrt(417)) / 8


def main():
    guesses = np.linspace(-3, 3, 30)
    cases = [{"x0": [g]} for g in guesses]

    start = time.perf_counter()
    results = fesd.batch.map(PROBLEM, overrides=cases)
    parallel_s = time.perf_counter() - start

    start = time.perf_counter()
    serial = [fesd.solve(PROBLEM, **case) for case in cases]
    serial_s = time.perf_counter() - start

    x0 = np.array([r.x0[0] if r.success else math.nan for r in results])
    reached = np.sum(np.abs(x0 - X0_STAR) < 1e-6)
    print(f"{reached}/{len(cases)} guesses reach x0* = {X0_STAR:.12f} "
          f"(largest error {np.nanmax(np.abs(x0 - X0_STAR)):.1e})")
    assert all(a.objective == b.objective for a, b in zip(results, serial) if a.success)
    print(f"wall time: Dask local cluster ({os.cpu_count()} workers) {parallel_s:.2f} s, "
          f"serial loop {serial_s:.2f} s")

    if len(sys.argv) > 1:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(guesses, x0, "o", label="FESD: x0* found")
        ax.axhline(X0_STAR, color="0.5", linestyle="--", label="exact x0*")
        ax.set_xlabel("initial guess of x0")
        ax.set_ylabel("x0*")
        ax.set_title("OCP (56) from 30 guesses (Fig. 9 right)")
        ax.legend()
        fig.tight_layout()
        fig.savefig(sys.argv[1])


if __name__ == "__main__":
    main()
