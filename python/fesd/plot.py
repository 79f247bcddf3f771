"""Plots of fesd results with matplotlib: what the fesd program's --plot pictures draw.

Use ``result.plot()`` (SimulationResult.plot, OcpResult.plot); matplotlib is imported only here,
so the rest of the package works without it (Debian: python3-matplotlib).
"""

import numpy as np


def _switch_label(s):
    def regions(r):
        return "{" + ",".join(str(i) for i in r) + "}"
    return f"{regions(s['before'])}->{regions(s['after'])}"


def _sliding_intervals(result):
    """(t_start, t_end) of runs of elements where a subsystem has two or more active regions (a
    projected system: where some constraint is active, i.e. in contact)."""
    subsystem = result.region_subsystem
    projected = getattr(result, "projected", False)
    out = []
    for n, active in enumerate(result.active_set):
        counts = {}
        for r in active:
            k = subsystem[r] if r < len(subsystem) else 0
            counts[k] = counts.get(k, 0) + 1
        if (projected and len(active) > 0) or any(c >= 2 for c in counts.values()):
            t0, t1 = result.t[n], result.t[n + 1]
            if out and out[-1][1] == t0:
                out[-1] = (out[-1][0], t1)
            else:
                out.append((t0, t1))
    return out


def _decorate(ax, result, label):
    for t0, t1 in _sliding_intervals(result):
        ax.axvspan(t0, t1, color="0.9", zorder=0)
    for i, s in enumerate(result.switches):
        ax.axvline(s["t"], color="0.4", linestyle="--", linewidth=0.8)
        if label:  # staggered in three rows: switches close together stay readable
            ax.annotate(_switch_label(s), xy=(s["t"], 1.0), xycoords=("data", "axes fraction"),
                        xytext=(2, -12 - 11 * (i % 3)), textcoords="offset points", fontsize=8,
                        color="0.3")


def _step_panel(ax, result, ylabel):
    h = np.asarray(result.h)
    if h.size == 0:
        return
    t = np.asarray(result.t)
    href = float(np.median(h))
    values, label = h, ylabel
    if np.all(np.abs(h / href - 1) < 1e-4):
        values, label = h / href - 1, f"{ylabel} / {href:.6g} - 1"
    ax.stairs(values, t[: h.size + 1], baseline=None, color="C0")
    if values is h and h.min() > 0 and h.max() / h.min() > 100:
        ax.set_yscale("log")
    ax.set_ylabel(label)


def _phase_box(result):
    """The trajectory's bounding box (element boundaries and stage points), 10 % wider on each
    side, as the program's phase portrait takes it."""
    pts = [np.asarray(result.x)[:, :2]]
    xs = np.asarray(result.x_stage)
    if xs.ndim == 2 and xs.shape[0] > 0 and xs.shape[1] >= 2:
        pts.append(xs[:, :2])
    pts = np.vstack(pts)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    box = []
    for j in range(2):
        if pts.shape[0] == 0:
            box += [-1.0, 1.0]
            continue
        lo, hi = float(pts[:, j].min()), float(pts[:, j].max())
        w = 0.1 * (hi - lo)
        if not w > 1e-12 * (1 + max(abs(lo), abs(hi))):
            w = max(0.1 * max(abs(lo), abs(hi)), 1e-3)
        box += [lo - w, hi + w]
    return box


def _switching_surfaces(result, box):
    """[(label, segments (k, 4))] of the model's switching surfaces in the box; [] when the
    result does not carry its problem (fesd.simulate/solve keep it for two-state systems)."""
    source = result.__dict__.get("_source")
    if source is None:
        return []
    from . import _fesd
    problem, pairs = source
    if pairs:
        problem = _fesd._with_overrides(problem, pairs)
    return _fesd._switching_surfaces(problem, *box)


def _phase_portrait(ax, result):
    x = np.asarray(result.x)
    box = _phase_box(result)
    # The surfaces on a square around the box, wider than it: the equal aspect widens the view.
    cx, cy = 0.5 * (box[0] + box[1]), 0.5 * (box[2] + box[3])
    half = 0.8 * max(box[1] - box[0], box[3] - box[2])
    for i, (label, seg) in enumerate(
            _switching_surfaces(result, [cx - half, cx + half, cy - half, cy + half])):
        xs = np.column_stack([seg[:, 0], seg[:, 2], np.full(len(seg), np.nan)]).ravel()
        ys = np.column_stack([seg[:, 1], seg[:, 3], np.full(len(seg), np.nan)]).ravel()
        ax.plot(xs, ys, color=str(0.45 + 0.1 * (i % 3)), linewidth=1.2, zorder=1, label=label)
    t = np.asarray(result.t)
    for k, (t0, t1) in enumerate(_sliding_intervals(result)):
        on = (t >= t0) & (t <= t1)
        ax.plot(x[on, 0], x[on, 1], color="C1", linewidth=6, alpha=0.5, zorder=2,
                solid_capstyle="round",
                label=("contact" if getattr(result, "projected", False) else "sliding")
                if k == 0 else None)
    ax.plot(x[:, 0], x[:, 1], color="C0", zorder=3, label="x(t)")
    ax.plot(x[0, 0], x[0, 1], "o", color="C0", markersize=4, zorder=3)
    for s in result.switches:
        i = int(np.searchsorted(result.t, s["t"]))
        if i < len(x):
            ax.plot(x[i, 0], x[i, 1], "x", color="C3", zorder=4)
    ax.set_xlim(box[0], box[1])
    ax.set_ylim(box[2], box[3])
    ax.set_xlabel(result.state_names[0])
    ax.set_ylabel(result.state_names[1])
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(loc="best", fontsize=8)
    ax.set_title("phase portrait", fontsize=10)


def plot(result, path=None, title=None):
    """Draws a SimulationResult or an OcpResult; returns the matplotlib Figure.

    Panels over time t, the switches as dashed vertical lines labelled with the regions active
    before and after ("{0}->{1}"), sliding elements shaded: the states x(t) at the element
    boundaries; for an OCP the controls (steps on the control grid) and the switching indicator
    eta_n of (31) (log scale; eta_n = 0, a switch, marked at the bottom); the step sizes h_n
    (h_n / h_ref - 1 when they all agree to 4 digits). A two-state system gets a phase portrait
    on the right, with the switching surfaces (c = 0, or g_i = g_j) and the sliding parts. ``path``: also saved there (PNG, SVG, PDF: by its suffix). ``title``: default
    the problem's name and status.
    """
    import matplotlib.pyplot as plt

    ocp = result.kind == "ocp"
    x = np.asarray(result.x)
    n_x = x.shape[1] if x.ndim == 2 else 0
    n_u = np.asarray(result.u).shape[1] if ocp and np.asarray(result.u).ndim == 2 else 0
    rows = ["x"] + (["u"] if n_u > 0 else []) + ["h"] + (["eta"] if ocp else [])
    # No portrait when one of the two states is the clock "t" (as the program's --plot).
    portrait = n_x == 2 and x.shape[0] > 1 and "t" not in list(result.state_names)[:2]
    fig = plt.figure(figsize=(15 if portrait else 10, 2.2 + 1.8 * len(rows)))
    grid = fig.add_gridspec(len(rows), 2 if portrait else 1,
                            width_ratios=[1.8, 1] if portrait else None,
                            height_ratios=[2] + [1] * (len(rows) - 1))
    axes = {}
    for i, row in enumerate(rows):
        axes[row] = fig.add_subplot(grid[i, 0], sharex=axes.get("x"))
    t = np.asarray(result.t)

    ax = axes["x"]
    for j in range(n_x):
        ax.plot(t, x[:, j], label=result.state_names[j] if j < len(result.state_names) else None)
    ax.set_ylabel("x")
    if n_x:
        ax.legend(loc="best", fontsize=8)
    _decorate(ax, result, label=True)

    if "u" in axes:
        ax = axes["u"]
        u = np.asarray(result.u)
        for j in range(n_u):
            ax.stairs(u[:, j], np.asarray(result.t_ctrl), baseline=None,
                      label=result.control_names[j] if j < len(result.control_names) else None)
        ax.set_ylabel("u")
        ax.legend(loc="best", fontsize=8)
        _decorate(ax, result, label=False)

    ax = axes["h"]
    _step_panel(ax, result, "h_n")
    if ocp:
        for tk in np.asarray(result.t_ctrl)[1:-1]:
            ax.axvline(tk, color="0.6", linestyle=":", linewidth=0.8)
    _decorate(ax, result, label=False)

    if "eta" in axes:
        ax = axes["eta"]
        eta = np.asarray(result.eta, dtype=float)
        t_eta = t[: eta.size]
        positive = np.isfinite(eta) & (eta > 0)
        zero = np.isfinite(eta) & (eta <= 0)
        if positive.any():
            ax.semilogy(t_eta[positive], eta[positive], ".", color="C0", markersize=4)
        if zero.any():
            ax.plot(t_eta[zero], np.full(zero.sum(), ax.get_ylim()[0]), "v", color="C3",
                    markersize=5, label="eta_n = 0 (switch)", clip_on=False)
            ax.legend(loc="best", fontsize=8)
        ax.set_ylabel("eta_n")
        _decorate(ax, result, label=False)

    axes[rows[-1]].set_xlabel("t")
    if portrait:
        _phase_portrait(fig.add_subplot(grid[:, 1]), result)
    fig.suptitle(title if title is not None else f"{result.name}: {result.status}")
    fig.tight_layout()
    if path is not None:
        fig.savefig(path)
    return fig


__all__ = ["plot"]
