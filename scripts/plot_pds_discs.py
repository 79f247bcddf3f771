#!/usr/bin/env python3
"""Frames of the collaborative manipulation OCP (papers/fesd-pds.txt Sect. IV-B, Fig. 3) with
gnuplot: the discs at several times from the JSON of `fesd solve examples/ocp_pds_discs.toml
--json FILE` or the CSV of `bench/pds_discs --csv FILE` (t and x at every stage point), as a PNG
of 6 panels and optionally an animated GIF.

    fesd solve examples/ocp_pds_discs.toml --json discs.json
    scripts/plot_pds_discs.py discs.json docs/img/pds_discs.png [--gif docs/img/pds_discs.gif]

Blue: actuator 1 (radius 1), orange: actuator 2 (radius 1), green: the pushed disc (radius 2);
transparent: the targets x_T; red strip: where no actuator centre may go (x_{1,1} <= -2.5,
x_{2,1} >= 2.5).
"""
import json
import subprocess
import sys

R = [1.0, 1.0, 2.0]
COLORS = ["#1f77b4", "#ff7f0e", "#2ca02c"]
TARGET = [(-10, 0), (10, 0), (0, 10)]


def read(path):
    if path.endswith(".json"):
        with open(path) as f:
            j = json.load(f)
        return [[0.0] + j["x"][0]] + [[t] + x for t, x in zip(j["t_stage"], j["x_stage"])]
    rows = []
    with open(path) as f:
        next(f)
        for line in f:
            v = [float(s) for s in line.split(",")]
            rows.append(v)
    return rows


def nearest(rows, t):
    return min(rows, key=lambda r: abs(r[0] - t))


def frame(row, title):
    cmds = [f'set title "{title}"']
    cmds.append("unset object")
    cmds.append('set object 1 rect from -2.5,-12 to 2.5,16 fc rgb "#ffcccc" fs solid 0.5 noborder back')
    k = 2
    for j in range(3):
        cmds.append(f'set object {k} circle at {TARGET[j][0]},{TARGET[j][1]} size {R[j]} '
                    f'fc rgb "{COLORS[j]}" fs transparent solid 0.15 noborder')
        k += 1
    for j in range(3):
        x, y = row[1 + 2 * j], row[2 + 2 * j]
        cmds.append(f'set object {k} circle at {x},{y} size {R[j]} fc rgb "{COLORS[j]}" '
                    f'fs solid 0.8 border lc rgb "black" front')
        k += 1
    cmds.append("plot NaN notitle")
    return "\n".join(cmds)


def main():
    args = sys.argv[1:]
    gif = None
    if "--gif" in args:
        i = args.index("--gif")
        gif = args[i + 1]
        del args[i:i + 2]
    if len(args) != 2:
        sys.exit(__doc__)
    rows = read(args[0])
    T = rows[-1][0]
    common = "\n".join([
        "set size ratio -1", "set xrange [-13:13]", "set yrange [-8:14]", "unset key",
        "set tics font ',8'"])
    times = [i * T / 5 for i in range(6)]
    script = [f'set terminal pngcairo size 1500,900 font ",10"', f'set output "{args[1]}"',
              common, 'set multiplot layout 2,3 title "Collaborative manipulation (fesd-pds Sect. IV-B)"']
    for t in times:
        r = nearest(rows, t)
        script.append(frame(r, f"t = {r[0]:.2f}"))
    script.append("unset multiplot")
    if gif:
        script += [f'set terminal gif animate delay 12 size 440,380 font ",10"', f'set output "{gif}"',
                   common]
        step = max(1, len(rows) // 60)
        for r in rows[::step] + [rows[-1]]:
            script.append(frame(r, f"t = {r[0]:.2f}"))
    script.append("set output")
    subprocess.run(["gnuplot"], input="\n".join(script), text=True, check=True)


if __name__ == "__main__":
    main()
