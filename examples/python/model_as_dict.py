"""A model given in Python, end to end: a relay feedback system with a Coulomb-like switch,
written as a dict of expressions (strings, as in problem files: derivatives stay exact and the
solves run without the GIL), simulated for several parameter values, then an OCP on the same
model. Nothing is read from or written to files.

    PYTHONPATH=build/python python3 examples/python/model_as_dict.py
"""
import math

import fesd

# Example 3 of the FESD paper with a parameter: x' in a - sign(x), x(0) = -1. For a > 1 the
# trajectory crosses x = 0 at t_s = 1 / (a + 1) and then x' = a - 1.
model = {
    "x": ["x"],
    "p": {"a": 2.0},
    "c": ["x"],            # region 0: x > 0, region 1: x < 0 (default S = [[1], [-1]])
    "F": [["a - 1"],       # x > 0
          ["a + 1"]],      # x < 0
    "x0": [-1.0],
}
simulation = {
    "name": "relay",
    "model": model,
    "simulation": {"T_sim": 1.0, "N_sim": 5},
    "discretization": {"rk_scheme": "radau_iia", "n_s": 2, "N_finite_elements": 3},
}


def main():
    for a in (1.5, 2.0, 4.0):
        r = fesd.simulate(simulation, p={"a": a})
        t_s = 1 / (a + 1)
        x_T = (a - 1) * (1 - t_s)
        print(f"a = {a}: {r.status}, t_s = {r.switch_times[0]:.12f} (exact {t_s:.12f}), "
              f"x(1) = {r.x[-1][0]:.12f} (exact {x_T:.12f})")

    # The sensitivity OCP (56) on the same model (a = 2): choose x0 to minimize
    # int_0^2 x^2 dt + (x(2) - 5/3)^2.
    ocp = {
        "name": "relay_ocp",
        "model": model,
        "ocp": {"T": 2.0, "f_q": "x^2", "f_q_T": "(x - 5/3)^2", "lbx0": [-math.inf],
                "ubx0": [math.inf], "initialization": "simulation"},
        "discretization": {"rk_scheme": "gauss_legendre", "n_s": 2, "N_finite_elements": 25},
        "homotopy": {"mpcc_mode": "scholtes_eq", "sigma_N": 1e-15, "complementarity_tol": 1e-12},
    }
    r = fesd.solve(ocp)
    print(f"OCP: {r.status}, x0* = {r.x0[0]:.12f} (exact {(9 - math.sqrt(417)) / 8:.12f}), "
          f"objective {r.objective:.12f}")
    print(fesd.to_toml(ocp))


if __name__ == "__main__":
    main()
