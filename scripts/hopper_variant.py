#!/usr/bin/env python3
"""Writes a variant of examples/nosnoc/hopper_ocp.toml (--step: hopper_ocp_step.toml) to stdout:
another goal x_goal, number of control intervals N_stages, one jump or several (--multijump:
round(x_goal - 0.1) jumps), with or without the reference as initial guess (--no_guess). The reference is, per jump, the parabola
through start, apex (x halfway, y = 1, l = 0.1) and landing (y = 0.5, l = 0.5) at s = 0, 1/2, 1
(nosnoc_py's three-point cubic spline with not-a-knot ends), sampled as nosnoc_py's hopper
scripts do; p_time_var gets the value at the end of every control interval. Used for rows 27 and
28 of docs/nosnoc-examples.md (scripts/hopper_sweep.py runs them):

  python3 scripts/hopper_variant.py --x_goal 3 --N_stages 60 --multijump > /tmp/hopper60.toml

(with --x_goal 5 --N_stages 50 --multijump it writes the example itself).
"""
import argparse
import pathlib
import re

NAMES = ["xr", "yr", "phir", "lr", "vxr", "vyr", "vphir", "vlr"]


def parabola(p0, pm, p1, s):
    return [a * (1 - s) * (1 - 2 * s) + b * 4 * s * (1 - s) + c * s * (2 * s - 1)
            for a, b, c in zip(p0, pm, p1)]


def reference(n, x_goal, multijump, height=1.0):
    x0 = [0.1, 0.5, 0, 0.5, 0, 0, 0, 0]
    if not multijump:
        xm = [(x_goal - 0.1) / 2 + 0.1, height, 0, 0.1, 0, 0, 0, 0]
        xe = [x_goal, 0.5, 0, 0.5, 0, 0, 0, 0]
        return [parabola(x0, xm, xe, i / n) for i in range(n + 1)]
    jumps = int(round(x_goal - 0.1))
    step = (x_goal - 0.1) / jumps
    per = n // jumps
    if per * jumps != n:
        raise SystemExit(f"N_stages = {n} is not a multiple of the {jumps} jumps")
    rows, start = [], x0
    for _ in range(jumps):
        mid = [start[0] + step / 2, height, 0, 0.1, 0, 0, 0, 0]
        end = [start[0] + step, 0.5, 0, 0.5, 0, 0, 0, 0]
        rows += [parabola(start, mid, end, i / per) for i in range(per)]
        start = end
    return rows + [start]


def num(v):
    return "%.10g" % (0.0 if abs(v) < 1e-14 else v)


def main():
    a = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    a.add_argument("--x_goal", type=float, default=5.0)
    a.add_argument("--N_stages", type=int, default=50)
    a.add_argument("--multijump", action="store_true")
    a.add_argument("--no_guess", action="store_true")
    a.add_argument("--step", action="store_true", help="the Heaviside step form (row 26's file)")
    args = a.parse_args()
    name = "hopper_ocp_step.toml" if args.step else "hopper_ocp.toml"
    base = pathlib.Path(__file__).resolve().parent.parent / "examples/nosnoc" / name
    text = base.read_text()
    n, T = args.N_stages, 5.0
    rows = reference(n, args.x_goal, args.multijump)
    text = re.sub(r"^N_stages = \d+", f"N_stages = {n}", text, count=1, flags=re.M)
    text = re.sub(r"^(p = \{.*?)x_goal = [0-9.]+", lambda m: m.group(1) + f"x_goal = {args.x_goal}",
                  text, count=1, flags=re.M)
    text = re.sub(r"^ubx = \[[0-9.]+,", f"ubx = [{num(args.x_goal + 0.1)},", text, count=1,
                  flags=re.M)
    guess = "x_guess = [\n" + ",\n".join(
        "  [" + ", ".join([num(v) for v in r] + [num(k * T / n)]) + "]"
        for k, r in enumerate(rows)) + "\n]\n"
    text = re.sub(r"x_guess = \[\n.*?\n\]\n", "" if args.no_guess else guess, text,
                  count=1, flags=re.S)
    table = "".join(f"{name} = [{', '.join(num(r[i]) for r in rows[1:])}]\n"
                    for i, name in enumerate(NAMES))
    text = re.sub(r"(\[ocp\.p_time_var\][^\n]*\n)(?:\w+ = \[[^\n]*\]\n)+", lambda m: m.group(1) + table,
                  text, count=1)
    print(text, end="")


if __name__ == "__main__":
    main()
