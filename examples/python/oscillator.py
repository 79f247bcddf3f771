"""The nonsmooth oscillator (47) from Python: simulate examples/oscillator.toml with overrides,
compare x(T) and the switch time with the exact solution and, with a file name, plot it:

    PYTHONPATH=build/python python3 examples/python/oscillator.py [oscillator.png]
"""
import os
import sys

import numpy as np

import fesd

HERE = os.path.dirname(os.path.abspath(__file__))
X_EXACT = np.array([-1.5974603774506984, -0.7614936206060108])  # x(pi/2), switch at t_s = 1


def main():
    problem = fesd.load(os.path.join(HERE, "..", "oscillator.toml"))
    for n_s in (2, 3, 4):  # Radau IIA of order 3, 5, 7
        r = fesd.simulate(problem, n_s=n_s, N_sim=40)
        print(f"n_s = {n_s}: {r.status}, |x(T) - x_exact| = "
              f"{np.linalg.norm(r.x[-1] - X_EXACT):.1e} (estimated "
              f"{r.accuracy['error_estimate']:.1e}), switch times - 1 = {r.switch_times - 1}")
    r = fesd.simulate(problem)
    print(r.full_report())
    if len(sys.argv) > 1:
        import matplotlib
        matplotlib.use("Agg")
        r.plot(sys.argv[1])


if __name__ == "__main__":
    main()
