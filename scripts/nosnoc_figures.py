#!/usr/bin/python3
"""fesd's counterparts of the figures that nosnoc_py's example scripts draw (docs/nosnoc-figures.md).

Runs `build/fesd simulate|solve` on the files of examples/nosnoc/ (each under a 120-s limit) and
writes one PNG per example into docs/img/nosnoc/: with fesd's own plot (`--plot`, shrunk with
Pillow to at most 480000 pixels) where the script's figure shows what that plot
shows, otherwise with matplotlib from the run's `--json` output (the panels the script draws:
theta and lambda, phase planes, the hysteresis plane, ...).

    scripts/nosnoc_figures.py                  # every figure (about 3 minutes on one core)
    scripts/nosnoc_figures.py relay two_gene   # only these
    scripts/nosnoc_figures.py --reuse          # redraw from the JSON of an earlier run

The JSON and fesd's raw plots go to build/nosnoc_figures/. The long rows (8, 10, 11, 24) are
not run here; rows 10, 23, 30 and 31 only with --long (docs/nosnoc-figures.md says why). Needs python3-matplotlib and Pillow
(hence /usr/bin/python3).
"""
import argparse
import json
import os
import subprocess
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from PIL import Image  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FESD = os.path.join(ROOT, "build", "fesd")
EXAMPLES = os.path.join(ROOT, "examples", "nosnoc")
OUT = os.path.join(ROOT, "docs", "img", "nosnoc")
WORK = os.path.join(ROOT, "build", "nosnoc_figures")
MAX_PIXELS = 480000  # about 800 x 600
FIGSIZE = (8, 6)  # inches at 100 dpi: 800 x 600 pixels

ARGS = None
TIMES = {}


def run(kind, stem, tag=None, extra=(), plot=False, limit=120):
    """Runs `fesd kind examples/nosnoc/stem.toml extra --json ...` (and `--plot`) and returns the
    parsed JSON (`limit`: seconds before the run is stopped). With --reuse an existing JSON is
    read instead."""
    tag = tag or stem
    js = os.path.join(WORK, tag + ".json")
    raw = os.path.join(WORK, tag + ".png")
    if not (ARGS.reuse and os.path.exists(js) and (not plot or os.path.exists(raw))):
        cmd = [FESD, kind, os.path.join(EXAMPLES, stem + ".toml"), *extra, "--json", js]
        if plot:
            cmd += ["--plot", raw]
        t0 = time.time()
        with open(os.path.join(WORK, tag + ".log"), "w") as log:
            subprocess.run(["timeout", str(limit), *cmd], stdout=log, stderr=subprocess.STDOUT, check=False)
        TIMES[tag] = time.time() - t0
        print(f"  {' '.join(os.path.relpath(c, ROOT) if c.startswith(ROOT) else c for c in cmd)}"
              f"  ({TIMES[tag]:.1f} s)")
    with open(js) as f:
        return json.load(f)


def compact(src, dst):
    """src -> dst: shrunk to at most MAX_PIXELS (Lanczos), 256 colours, no metadata."""
    im = Image.open(src).convert("RGB")
    scale = min(1.0, (MAX_PIXELS / (im.width * im.height)) ** 0.5)
    if scale < 1.0:
        im = im.resize((round(im.width * scale), round(im.height * scale)), Image.LANCZOS)
    im.quantize(256, method=Image.MEDIANCUT).save(dst, optimize=True)
    print(f"  -> {os.path.relpath(dst, ROOT)} {im.width}x{im.height} "
          f"({os.path.getsize(dst) // 1024} KB)")


def shrink(tag, name):
    """fesd's raw plot of run `tag` -> docs/img/nosnoc/name.png."""
    compact(os.path.join(WORK, tag + ".png"), os.path.join(OUT, name + ".png"))


def own_plot(command, tag):
    """fesd's own plot (`fesd simulate|solve FILE --plot`) of examples/nosnoc/tag.toml, shrunk to
    docs/img/nosnoc/tag.png."""
    run(command, tag, plot=True)
    shrink(tag, tag)


def save(fig, name, title):
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    dst = os.path.join(OUT, name + ".png")
    raw = os.path.join(WORK, name + "_mpl.png")
    fig.savefig(raw, dpi=100)
    plt.close(fig)
    compact(raw, dst)


def arr(d, key):
    return np.array(d[key], dtype=float)


def boundaries(d):
    """Element boundaries t_n of a run (the t of its JSON)."""
    return arr(d, "t")


def switch_lines(ax, d):
    for ts in d.get("switch_times", []):
        ax.axvline(ts, color="0.4", linestyle="--", linewidth=0.8)


def control_steps(ax, d, i, label):
    """u_i as steps on the control grid (value of interval k on [t_k, t_{k+1}])."""
    tc = arr(d, "t_ctrl")
    u = arr(d, "u")[:, i]
    ax.step(tc, np.concatenate([u, u[-1:]]), where="post", label=label)


# ---- rows 1-3: x, lambda and theta over t ----------------------------------------------------
def theta_lambda_figure(d, name, title):
    t = boundaries(d)
    ts = arr(d, "t_stage")
    lam, th = arr(d, "lambda"), arr(d, "theta")
    fig, axes = plt.subplots(3, 1, figsize=FIGSIZE, sharex=True)
    axes[0].plot(t, arr(d, "x")[:, 0], marker="o", markersize=3, label="x")
    axes[0].set_ylabel("x")
    for i in range(lam.shape[1]):
        axes[1].plot(ts, lam[:, i], marker=".", label=f"lambda_{i}")
        axes[2].plot(ts, th[:, i], marker=".", label=f"theta_{i}")
    axes[1].set_ylabel("lambda (stage points)")
    axes[2].set_ylabel("theta (stage points)")
    axes[2].set_xlabel("t")
    for tn in t:
        axes[2].axvline(tn, color="0.6", linestyle=":", linewidth=0.8)
    for ax in axes:
        switch_lines(ax, d)
        ax.grid(True)
        ax.legend(loc="best", fontsize=8)
    save(fig, name, title)


def fig_simplest():
    d = run("simulate", "simplest_example")
    theta_lambda_figure(d, "simplest_example",
                        "simplest_example.toml: x' = 3 (x < 0), 1 (x > 0), x(0) = -1")


def fig_parametric():
    d = run("simulate", "parametric_example")
    theta_lambda_figure(d, "parametric_example",
                        "parametric_example.toml: x' = 3 (x < 0), p = -1 (x > 0): sliding on x = 0")


def fig_switch_cases():
    d = run("simulate", "different_switch_cases")
    theta_lambda_figure(d, "different_switch_cases",
                        "different_switch_cases.toml ('spontaneous'): x' = -1 (x < 0), 1 (x > 0), x(0) = 0")


# ---- row 4: relay feedback: fesd's plot of the states, and lambda, theta ----------------------
def fig_relay():
    d = run("simulate", "relay_feedback", plot=True)
    shrink("relay_feedback", "relay_feedback")
    ts = arr(d, "t_stage")
    lam, th = arr(d, "lambda"), arr(d, "theta")
    fig, axes = plt.subplots(2, 1, figsize=FIGSIZE, sharex=True)
    for i in range(lam.shape[1]):
        axes[0].plot(ts, lam[:, i], linewidth=0.8, label=f"lambda_{i}")
        axes[1].plot(ts, th[:, i], linewidth=0.8, label=f"theta_{i}")
    axes[0].set_ylabel("lambda")
    axes[1].set_ylabel("theta")
    axes[1].set_xlabel("t")
    for ax in axes:
        ax.grid(True)
        ax.legend(loc="upper right", fontsize=8)
    save(fig, "relay_feedback_algebraic",
         "relay_feedback.toml: Stewart's lambda and theta at the stage points")


# ---- rows 5-7 with fesd's own plot ------------------------------------------------------------
def fig_friction_block():
    own_plot("simulate", "friction_block")


def fig_oscillator():
    own_plot("simulate", "oscillator_example")


def fig_stick_slip():
    own_plot("simulate", "periodic_stick_slip_codim1")
    d = run("simulate", "periodic_stick_slip")
    t, x = boundaries(d), arr(d, "x")
    fig = plt.figure(figsize=FIGSIZE)
    for i in range(3):
        ax = fig.add_subplot(2, 3, i + 1)
        ax.plot(t, x[:, i])
        switch_lines(ax, d)
        ax.set_xlabel("t")
        ax.set_ylabel(f"x{i + 1}(t)")
        ax.grid(True)
    ax = fig.add_subplot(2, 1, 2)
    ax.plot(x[:, 0], x[:, 2])
    ax.set_xlabel("x1")
    ax.set_ylabel("x3")
    ax.grid(True)
    save(fig, "periodic_stick_slip",
         "periodic_stick_slip.toml (codim 2): states over t (switches dashed) and x3 over x1")


# ---- row 9: the temperature control simulation ------------------------------------------------
def fig_temperature():
    d = run("simulate", "temperature_control")
    t, x = boundaries(d), arr(d, "x")
    y, w, clock = x[:, 0], x[:, 1], x[:, 2]
    y1, y2 = 17.0, 21.0
    psi = (y - y1) / (y2 - y1)
    centres = [(0.25, -0.25), (0.25, 0.25), (0.75, 0.75), (0.75, 1.25)]
    fig, axes = plt.subplots(2, 2, figsize=FIGSIZE)
    ax = axes[0, 0]
    ax.axhline(y1, color="k", linestyle="--", linewidth=0.8)
    ax.axhline(y2, color="k", linestyle="--", linewidth=0.8)
    ax.plot(t, y, "k", label="y (temperature)")
    ax.plot(t, w, label="w (auxiliary)")
    ax.plot(t, clock, label="t (physical time)")
    ax.set_xlabel("simulation time")
    ax.set_ylabel("x")
    ax.legend(fontsize=8)
    ax.grid(True)
    ax = axes[0, 1]
    ax.plot(clock, y)
    ax.set_xlabel("physical time t")
    ax.set_ylabel("temperature y")
    ax.grid(True)
    ax = axes[1, 0]
    for i, (a, b) in enumerate(centres):
        ax.plot(t, (psi - a) ** 2 + (w - b) ** 2, label=f"g_{i} (region {i})")
    ax.set_xlabel("simulation time")
    ax.set_ylabel("g")
    ax.legend(fontsize=8)
    ax.grid(True)
    ax = axes[1, 1]
    hysteresis_plane(ax, fig, psi, w, t)
    save(fig, "temperature_control",
         "temperature_control.toml (u = 20): states, y over physical time, g_i, the (psi, w) plane")


def hysteresis_plane(ax, fig, psi, w, t):
    ax.plot([-2, 1], [0, 0], "k", linewidth=1)
    ax.plot([0, 2], [1, 1], "k", linewidth=1)
    ax.plot([-1, 0, 1, 2], [1.5, 1, 0, -0.5], "k", linewidth=1)
    im = ax.scatter(psi, w, c=t, cmap="hot", s=12, edgecolors="0.5", linewidths=0.3)
    fig.colorbar(im, ax=ax, label="simulation time")
    ax.set_xlabel("psi")
    ax.set_ylabel("w")
    ax.set_xlim(min(-0.3, psi.min() - 0.1), max(1.3, psi.max() + 0.1))
    ax.set_ylim(-0.3, 1.3)


# ---- row 10 (opt-in, --long: 275 s CPU): IRMA, x_i over t with the thresholds ------------------
def fig_irma():
    d = run("simulate", "irma", extra=ARGS.irma_extra, limit=1800)
    t, x = boundaries(d), arr(d, "x")
    thresholds = [[0.01], [0.01, 0.06, 0.08], [0.035], [0.04], [0.01]]
    fig, axes = plt.subplots(5, 1, figsize=FIGSIZE, sharex=True)
    for i, ax in enumerate(axes):
        ax.plot(t, x[:, i], linewidth=1)
        for c in thresholds[i]:
            ax.axhline(c, color="k", linestyle=":", linewidth=0.8)
        ax.set_xlim(t[0], t[-1])
        ax.set_ylim(0, 1.1 * x[:, i].max())
        ax.set_ylabel(f"x{i + 1}")
    axes[-1].set_xlabel("t")
    save(fig, "irma", f"irma.toml over [{t[0]:g}, {t[-1]:g}]: x_i and their thresholds (dotted)")


# ---- row 12: the two-gene network from 16 initial states --------------------------------------
def fig_two_gene():
    fig, ax = plt.subplots(figsize=(6.5, 6))
    for a in (3, 6, 9, 12):
        for b in (3, 6, 9, 12):
            d = run("simulate", "two_gene", tag=f"two_gene_{a}_{b}", extra=["--x0", f"{a},{b}"])
            x = arr(d, "x")
            # one arrow per integration step (N_FE = 2 elements each), as the script's quiver
            xs = x[::2]
            line, = ax.plot(x[:, 0], x[:, 1], linewidth=1)
            ax.quiver(xs[:-1, 0], xs[:-1, 1], np.diff(xs[:, 0]), np.diff(xs[:, 1]), angles="xy",
                      scale_units="xy", scale=1, width=0.004, color=line.get_color())
    for c in (4, 8):
        ax.axvline(c, color="k", linestyle=":", linewidth=0.8)
        ax.axhline(c, color="k", linestyle=":", linewidth=0.8)
    ax.set_xlim(0, 13)
    ax.set_ylim(0, 13)
    ax.set_xlabel("x1")
    ax.set_ylabel("x2")
    save(fig, "two_gene", "two_gene.toml from x0 in {3, 6, 9, 12}^2 over [0, 1] (thresholds dotted)")


# ---- row 13: the particle ---------------------------------------------------------------------
def fig_particle():
    d = run("solve", "particle")
    x = arr(d, "x")
    fig, axes = plt.subplots(1, 2, figsize=(8, 4))
    axes[0].plot(x[:, 0], x[:, 1], marker=".", markersize=3)
    axes[0].set_xlabel("qx")
    axes[0].set_ylabel("qy")
    axes[1].plot(x[:, 4], x[:, 2], label="vx")
    axes[1].plot(x[:, 4], x[:, 3], label="vy")
    axes[1].set_xlabel("clock t (physical time)")
    axes[1].legend(fontsize=8)
    for ax in axes:
        ax.grid(True)
    save(fig, "particle", "particle.toml: the path (qy over qx) and vx, vy over the physical time")


# ---- rows 14/15, 19, 21: OCPs with the script's panels ----------------------------------------
def fig_motor():
    d = run("solve", "motor_with_friction", plot=True)
    shrink("motor_with_friction", "motor_with_friction_fesd")  # h_n: the script's time-step figure
    t, x = boundaries(d), arr(d, "x")
    fig, axes = plt.subplots(4, 1, figsize=FIGSIZE, sharex=True)
    axes[0].plot(t, x[:, 0], label="x1")
    axes[0].plot(t, x[:, 2], label="x2")
    axes[0].set_ylabel("x")
    axes[1].plot(t, x[:, 1], label="v1")
    axes[1].plot(t, x[:, 3], label="v2")
    axes[1].set_ylabel("v")
    axes[2].plot(t, x[:, 4], label="I")
    axes[2].set_ylabel("I")
    control_steps(axes[3], d, 0, "u")
    axes[3].set_ylabel("u")
    axes[3].set_xlabel("time [s]")
    for ax in axes:
        switch_lines(ax, d)
        ax.grid(True)
        ax.legend(loc="upper right", fontsize=8)
    save(fig, "motor_with_friction",
         f"motor_with_friction.toml: J = {d['objective']:.6f}, switches of v1 dashed")


def fig_car(name, controls):
    """q and v (v = 15 dotted) over t, then one panel per control (index, label) as steps."""
    d = run("solve", name)
    t, x = boundaries(d), arr(d, "x")
    fig, axes = plt.subplots(2 + len(controls), 1, figsize=FIGSIZE, sharex=True)
    axes[0].plot(t, x[:, 0])
    axes[0].set_ylabel("q")
    axes[1].plot(t, x[:, 1])
    axes[1].axhline(15, color="k", linestyle=":", linewidth=0.8)
    axes[1].set_ylabel("v")
    for ax, (index, label) in zip(axes[2:], controls):
        control_steps(ax, d, index, label)
        ax.set_ylabel(label)
    axes[-1].set_xlabel("time [s]")
    for ax in axes:
        switch_lines(ax, d)
        ax.grid(True)
    save(fig, name, f"{name}.toml: J = {d['objective']:.6f} (v = 15 dotted, switches dashed)")


def fig_simple_car():
    fig_car("simple_car_algebraic", [(0, "u")])


def fig_car_control():
    fig_car("car_control_complementarity", [(0, "u_a"), (1, "u_b")])


# ---- rows 16, 17, 20 with fesd's own plot -----------------------------------------------------
def fig_cart_pole():
    own_plot("solve", "cart_pole_with_friction")
    own_plot("solve", "main_cartpole")


def fig_sliding_mode():
    own_plot("solve", "ocp_sliding_mode_nosnoc")


# ---- row 29: the hysteresis car ---------------------------------------------------------------
def fig_hysteresis_car():
    # One NLP fails with fesd's sparse_ldl and is retried (homotopy_retries): docs/nosnoc-examples.md,
    # row 29.
    d = run("solve", "hysteresis_car_control_time_optimal")
    t, x = boundaries(d), arr(d, "x")
    names = ["q (position)", "v (speed)", "L (fuel)", "w (auxiliary)", "t (time)"]
    fig, axes = plt.subplots(2, 2, figsize=FIGSIZE)
    ax = axes[0, 0]
    for i, n in enumerate(names):
        ax.plot(t, x[:, i], label=n)
    ax.set_xlabel("simulation time")
    ax.legend(fontsize=7)
    ax = axes[0, 1]
    control_steps(ax, d, 0, "u")
    control_steps(ax, d, 1, "s")
    ax.set_xlabel("simulation time")
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    ax.plot(x[:, 4], x[:, 0])
    ax.set_xlabel("physical time t")
    ax.set_ylabel("q")
    ax = axes[1, 1]
    hysteresis_plane(ax, fig, (x[:, 1] - 10.0) / 5.0, x[:, 3], t)
    for a in axes.flat:
        a.grid(True)
    save(fig, "hysteresis_car_control_time_optimal",
         f"hysteresis_car_control_time_optimal.toml: objective {d['objective']:.4f}, "
         f"t(T) = {x[-1, 4]:.3f}")


# ---- rows 30, 31 (opt-in, --long: 165 s and 440 s): the gearboxes with 3 and 4 gears ----------
def voronoi_plane(ax, fig, points, psi, w, t):
    """The script's (psi, w) plane: the Voronoi generators (x) and the trajectory by time."""
    ax.scatter(points[:, 0], points[:, 1], marker="x", color="k", s=30, label="generators")
    im = ax.scatter(psi, w, c=t, cmap="hot", s=12, edgecolors="0.5", linewidths=0.3)
    fig.colorbar(im, ax=ax, label="simulation time")
    ax.set_xlabel("psi")
    ax.legend(fontsize=7)


def gearbox_figure(stem, names, psi, w_plane, w_label, points, extra_axis=None):
    d = run("solve", stem, limit=1800)
    t, x = boundaries(d), arr(d, "x")
    # Without extra_axis 2 x 2 panels; with it the top row holds the three time panels and the
    # bottom row the plane and the extra (3-D) axis.
    fig = plt.figure(figsize=(10, 7) if extra_axis else FIGSIZE)
    if extra_axis:
        gs = fig.add_gridspec(2, 6)
        cells = [gs[0, 0:2], gs[0, 2:4], gs[0, 4:6], gs[1, 0:3], gs[1, 3:6]]
    else:
        gs = fig.add_gridspec(2, 2)
        cells = [gs[0, 0], gs[0, 1], gs[1, 0], gs[1, 1]]
    ax = fig.add_subplot(cells[0])
    for i, n in enumerate(names):
        ax.plot(t, x[:, i], label=n)
    ax.set_xlabel("simulation time")
    ax.legend(fontsize=7)
    ax = fig.add_subplot(cells[1])
    control_steps(ax, d, 0, "u")
    ax.set_xlabel("simulation time")
    ax.legend(fontsize=8)
    ax = fig.add_subplot(cells[2])
    ax.plot(x[:, -1], x[:, 0])
    ax.set_xlabel("physical time t")
    ax.set_ylabel("q")
    ax = fig.add_subplot(cells[3])
    voronoi_plane(ax, fig, points, psi(x), w_plane(x), t)
    ax.set_ylabel(w_label)
    if extra_axis:
        extra_axis(fig.add_subplot(cells[4], projection="3d"), x, t)
    for a in fig.axes:
        if a.name != "3d":
            a.grid(True)
    s = d.get("v_global", {})
    s = s.get("s", s) if isinstance(s, dict) else s
    save(fig, stem, f"{stem}.toml: {d['status']}, objective {d['objective']:.4f}, "
         f"t(T) = {x[-1, -1]:.3f}, s = {float(np.ravel(s)[0]):.4f}")


def fig_gearbox_2d():
    shift = 0.6  # psi_shift_2 of the script
    base = [(0.25, -0.25), (0.25, 0.25), (0.75, 0.75), (0.75, 1.25)]
    points = np.array(base + [(a + shift, b + 1) for a, b in base])
    gearbox_figure("hysteresis_car_control_time_optimal_2d",
                   ["q (position)", "v (speed)", "L (fuel)", "w (auxiliary)", "t (time)"],
                   lambda x: (x[:, 1] - 5.0) / 5.0, lambda x: x[:, 3], "w", points)


def fig_gearbox_3d():
    shift, a = 1.5, 0.25  # the script's control() defaults, mode TYPE_PAPER
    z = [(a, -a, 0), (a, a, 0), (1 - a, 1 - a, 0), (1 - a, 1 + a, 0),
         (a + shift, 1, -a), (a + shift, 1, a), (1 - a + shift, 1, 1 - a), (1 - a + shift, 1, 1 + a),
         (a + 2 * shift, 1 - a, 1), (a + 2 * shift, 1 + a, 1), (1 - a + 2 * shift, 2 - a, 1),
         (1 - a + 2 * shift, 2 + a, 1)]
    points = np.array([(p, w1 + w2) for p, w1, w2 in z])  # the script's 2-D view: w1 + w2

    def line_3d(ax, x, t):
        psi = (x[:, 1] - 5.0) / 5.0
        ax.scatter(psi, x[:, 3], x[:, 4], c=t, cmap="hot", s=8)
        ax.set_xlabel("psi")
        ax.set_ylabel("w1")
        ax.set_zlabel("w2")

    gearbox_figure("hysteresis_car_control_time_optimal_3d",
                   ["q (position)", "v (speed)", "L (fuel)", "w1", "w2", "t (time)"],
                   lambda x: (x[:, 1] - 5.0) / 5.0, lambda x: x[:, 3] + x[:, 4], "w1 + w2",
                   points, extra_axis=line_3d)


# ---- row 23 (opt-in, --long: 240 s): the elastic ball in a box -------------------------------
def fig_elastic_ball():
    d = run("solve", "elastic_ball_in_box", limit=1800)
    t, x = boundaries(d), arr(d, "x")
    clock = x[:, 4]
    # The script plots the points of the elements in free flight (theta of the interior > 0.1):
    # the wall regions freeze the clock, and their states are the auxiliary dynamics'.
    flight = np.concatenate([[True], [0 in a for a in d["active_set"]]])
    omega, a0, R = -3.0 * np.pi, np.pi / 4.0, 1.0
    tt = np.linspace(0.0, clock[-1], 400)
    ref_q = R * np.sin(omega * tt + a0), R * np.cos(omega * tt + a0)
    ref_v = R * omega * np.cos(omega * tt + a0), -R * omega * np.sin(omega * tt + a0)
    fig, axes = plt.subplots(2, 2, figsize=FIGSIZE)
    ax = axes[0, 0]
    ax.plot(ref_q[0], ref_q[1], "r--", linewidth=0.8, label="reference")
    ax.plot(x[:, 0], x[:, 1], color="0.7", linewidth=0.8, label="in a wall (clock frozen)")
    ax.plot(np.where(flight, x[:, 0], np.nan), np.where(flight, x[:, 1], np.nan), "b",
            label="flight")
    left, right, bottom, top = -1.2, 1.1, -1.05, 1.15  # the walls
    ax.plot([left, right, right, left, left], [bottom, bottom, top, top, bottom], "k", linewidth=1)
    ax.set_aspect("equal")
    ax.set_xlabel("qx")
    ax.set_ylabel("qy")
    ax.legend(fontsize=6, loc="lower left")
    for ax, (i, j), ref, name in ((axes[0, 1], (0, 1), ref_q, "q"),
                                  (axes[1, 0], (2, 3), ref_v, "v")):
        for k, c in ((i, "b"), (j, "r")):
            ax.plot(clock[flight], x[flight, k], c, marker=".", markersize=2,
                    label=d["state_names"][k])
        ax.plot(tt, ref[0], "b:", tt, ref[1], "r:")
        ax.set_xlabel("physical time t (clock)")
        ax.set_ylabel(name + " (dotted: reference)")
        ax.legend(fontsize=7)
    ax = axes[1, 1]
    control_steps(ax, d, 0, "ux")
    control_steps(ax, d, 1, "uy")
    u = arr(d, "u")
    norm = np.hypot(u[:, 0], u[:, 1])
    ax.step(arr(d, "t_ctrl"), np.concatenate([norm, norm[-1:]]), where="post",
            color="0.5", linewidth=0.8, label="|u| (<= 50)")
    ax.set_xlabel("t")
    ax.legend(fontsize=7)
    for a in axes.flat:
        a.grid(True)
    impacts = sum(1 for sw in d["switches"] if sw["before"] == [0])
    save(fig, "elastic_ball_in_box",
         f"elastic_ball_in_box.toml: {d['status']}, objective {d['objective']:.4f}, "
         f"{impacts} wall contacts")


FIGURES = {
    "simplest": fig_simplest,
    "parametric": fig_parametric,
    "switch_cases": fig_switch_cases,
    "relay": fig_relay,
    "friction_block": fig_friction_block,
    "stick_slip": fig_stick_slip,
    "oscillator": fig_oscillator,
    "temperature": fig_temperature,
    "two_gene": fig_two_gene,
    "particle": fig_particle,
    "motor": fig_motor,
    "cart_pole": fig_cart_pole,
    "simple_car": fig_simple_car,
    "sliding_mode": fig_sliding_mode,
    "car_control": fig_car_control,
    "hysteresis_car": fig_hysteresis_car,
}
LONG = {"irma": fig_irma, "elastic_ball": fig_elastic_ball, "gearbox_2d": fig_gearbox_2d,
        "gearbox_3d": fig_gearbox_3d}


def main():
    global ARGS
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("only", nargs="*", help=f"figures to draw (default all): {', '.join(FIGURES)}")
    parser.add_argument("--reuse", action="store_true", help="redraw from existing JSON")
    parser.add_argument("--long", action="store_true",
                        help=f"also the long runs ({', '.join(LONG)}: minutes, not in the default set)")
    parser.add_argument("--irma-extra", nargs=argparse.REMAINDER, default=[],
                        help="overrides for the IRMA run (e.g. --T_sim 100 --N_sim 50 to try it)")
    ARGS = parser.parse_args()
    FIGURES.update(LONG if ARGS.long or any(n in LONG for n in ARGS.only) else {})
    unknown = [n for n in ARGS.only if n not in FIGURES]
    if unknown:
        sys.exit(f"unknown figure(s) {unknown}; known: {', '.join(FIGURES)}, {', '.join(LONG)}")
    if not os.access(FESD, os.X_OK):
        sys.exit(f"{FESD} not found: build fesd_cli first")
    os.makedirs(OUT, exist_ok=True)
    os.makedirs(WORK, exist_ok=True)
    for name in ARGS.only or FIGURES:
        print(name)
        FIGURES[name]()


if __name__ == "__main__":
    main()
