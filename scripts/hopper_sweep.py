#!/usr/bin/env python3
"""Runs nosnoc_py's two hopper sweeps with fesd (docs/nosnoc-examples.md, rows 27 and 28).

  ns      examples/hopper_robot/ns_experiment.py: x_goal = 3, one jump, 50 control intervals,
          n_s = 2..7, the reference not used as guess; the step form and Stewart's form.
  stages  examples/hopper_robot/stage_experiment.py: x_goal = 3, three jumps, n_s = 2,
          N_stages = 60, 66, ..., 108, the reference as guess; both forms.

Each point writes its variant with scripts/hopper_variant.py into a temporary directory, runs
`fesd solve VARIANT --json OUT` and reads status, objective, IPOPT iterations and the CPU time of
the NLPs (the sum over the homotopy, as nosnoc_py's cpu_time_nlp). It prints one row per point;
--csv writes them, each as soon as its point has finished (a point takes 10-40 min of CPU time),
and --resume keeps the finished rows of that file and runs the other points (missing ones, and
those that ended by --timeout or without a result: their rows are dropped), so a sweep can be
run in pieces; --keep DIR keeps each point's problem file, JSON result (the homotopy's rows:
which NLPs were retried and how) and log (the report, and while it runs a progress line every
30 s); --plot draws the scripts' two figures (CPU time, and CPU time per IPOPT iteration, over
n_s or N, step form against Stewart's); --report runs nothing: it prints --csv's rows as a
Markdown table (the one in docs/nosnoc-examples.md) and draws --plot from them. Nothing is
written unless asked.

  python3 scripts/hopper_sweep.py ns --points 2,3 --csv /tmp/ns.csv --plot /tmp/ns.png
  python3 scripts/hopper_sweep.py ns --csv /tmp/ns.csv --resume      # the other points
  python3 scripts/hopper_sweep.py ns --csv /tmp/ns.csv --report --plot /tmp/ns.png
"""
import argparse
import contextlib
import csv
import json
import os
import pathlib
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
EXPERIMENTS = {
    # name: (swept key, default points, variant flags, per form: no reference guess?)
    "ns": ("n_s", [2, 3, 4, 5, 6, 7], ["--x_goal", "3"], {"step": True, "stewart": True}),
    "stages": ("N_stages", [60, 66, 72, 78, 84, 90, 96, 102, 108],
               ["--x_goal", "3", "--multijump"], {"step": False, "stewart": False}),
}
FIELDS = ["form", "key", "value", "status", "objective", "comp_residual", "nlps", "ipopt_iterations",
          "cpu_nlp_s", "cpu_per_iteration_s", "wall_s", "x_final"]


def variant(form, key, value, flags, no_guess, directory):
    args = [sys.executable, str(ROOT / "scripts/hopper_variant.py")] + flags
    if key == "N_stages":
        args += ["--N_stages", str(value)]
    if no_guess:
        args.append("--no_guess")
    if form == "step":
        args.append("--step")
    text = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    path = pathlib.Path(directory) / f"hopper_{form}_{key}_{value}.toml"
    path.write_text(text)
    return path


def run_point(fesd, form, key, value, flags, no_guess, timeout, directory, keep):
    path = variant(form, key, value, flags, no_guess, directory)
    out = path.with_suffix(".json")
    # Kept points log the report and the progress lines (an NLP's IPOPT iteration every 30 s)
    # as they come, so a long point can be followed with tail -f.
    cmd = [fesd, "solve", str(path), "--json", str(out)] + ([] if keep else ["--quiet"])
    if key == "n_s":
        cmd += ["--n_s", str(value)]
    start = time.monotonic()
    try:
        with open(path.with_suffix(".log"), "w") if keep else open(os.devnull, "w") as log:
            code = subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT,
                                  timeout=timeout).returncode
    except subprocess.TimeoutExpired:
        code = None
    wall = time.monotonic() - start
    row = dict(form=form, key=key, value=value, wall_s=round(wall, 1))
    if code is None or not out.exists():
        row["status"] = "timeout" if code is None else f"exit {code}"
        return row
    r = json.loads(out.read_text())
    rows = r.get("homotopy", [])
    iterations = sum(h["nlp_iterations"] for h in rows)
    cpu = sum(h["cpu_s"] for h in rows)
    row.update(status=r["status"], objective=r["objective"],
               comp_residual=r["stats"]["comp_residual"], nlps=len(rows),
               ipopt_iterations=iterations, cpu_nlp_s=round(cpu, 2),
               cpu_per_iteration_s=round(cpu / iterations, 4) if iterations else None,
               x_final=" ".join("%.4g" % v for v in r["x_final"]))
    return row


def plot(rows, key, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    for form, style in (("step", "Xb-"), ("stewart", "Xr-")):
        pts = sorted((r for r in rows if r["form"] == form and r.get("cpu_nlp_s") is not None),
                     key=lambda r: r["value"])
        label = "Step" if form == "step" else "Stewart"
        axes[0].plot([r["value"] for r in pts], [r["cpu_nlp_s"] for r in pts], style, label=label)
        axes[1].plot([r["value"] for r in pts], [r["cpu_per_iteration_s"] for r in pts], style,
                     label=label)
    name = "$n_s$" if key == "n_s" else "$N$ (control intervals)"
    axes[0].set_ylabel("CPU time of the NLPs [s]")
    axes[1].set_ylabel("CPU time per IPOPT iteration [s]")
    for ax in axes:
        ax.set_xlabel(name)
        ax.grid(True)
        ax.legend(loc="best")
    fig.suptitle(f"fesd, hopper, x_goal = 3: sweep over {key}")
    fig.tight_layout()
    fig.savefig(path, dpi=80)


def markdown(rows, key):
    """The rows as the Markdown table of docs/nosnoc-examples.md, by point and form."""
    name = "n_s" if key == "n_s" else "N"
    lines = [f"| {name} | form | status | objective | qx(T) | NLPs | IPOPT iterations | CPU s "
             "| CPU s per iteration |", "|---:|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in sorted(rows, key=lambda r: (r["value"], r["form"])):
        def cell(k, fmt):
            return fmt % r[k] if r.get(k) is not None else "-"
        qx = r["x_final"].split()[0] if r.get("x_final") else "-"
        lines.append(f"| {r['value']} | {'Stewart' if r['form'] == 'stewart' else 'step'} | "
                     f"{r['status']} | {cell('objective', '%.6g')} | {qx} | {cell('nlps', '%d')} "
                     f"| {cell('ipopt_iterations', '%d')} | {cell('cpu_nlp_s', '%.0f')} | "
                     f"{cell('cpu_per_iteration_s', '%.3f')} |")
    return "\n".join(lines)


def read_rows(path, key):
    """The rows of an earlier run's CSV (numbers back as numbers), for --resume."""
    if not pathlib.Path(path).exists():
        return []
    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            if r.get("key") != key:
                sys.exit(f"--resume: {path} holds a sweep over {r.get('key')}, not {key}")
            r = {k: v for k, v in r.items() if v not in (None, "")}
            r["value"] = int(r["value"])
            for k in ("objective", "comp_residual", "cpu_nlp_s", "cpu_per_iteration_s", "wall_s"):
                if k in r:
                    r[k] = float(r[k])
            for k in ("nlps", "ipopt_iterations"):
                if k in r:
                    r[k] = int(r[k])
            rows.append(r)
    return rows


def main():
    a = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    a.add_argument("experiment", choices=sorted(EXPERIMENTS))
    a.add_argument("--points", help="comma-separated values of n_s or N_stages (default: the script's)")
    a.add_argument("--forms", default="step,stewart", help="step, stewart or both (default)")
    a.add_argument("--fesd", default=str(ROOT / "build/fesd"))
    a.add_argument("--timeout", type=float, default=3600, help="seconds per point")
    a.add_argument("--csv", help="write the rows as CSV, each when its point has finished")
    a.add_argument("--resume", action="store_true",
                   help="keep the finished rows of --csv's file and run only the other points")
    a.add_argument("--plot", help="draw the scripts' two figures (PNG/SVG)")
    a.add_argument("--report", action="store_true",
                   help="run nothing: print --csv's rows as a Markdown table (and draw --plot)")
    a.add_argument("--keep", metavar="DIR",
                   help="keep each point's problem file, JSON result and log in DIR (default: "
                        "a temporary directory, removed at the end)")
    args = a.parse_args()
    key, points, flags, no_guess = EXPERIMENTS[args.experiment]
    if args.points:
        try:
            points = [int(v) for v in args.points.split(",")]
        except ValueError:
            a.error(f"--points: not a list of integers: '{args.points}'")
    forms = args.forms.split(",")
    for f in forms:
        if f not in no_guess:
            a.error(f"--forms: unknown form '{f}' (step, stewart)")
    if args.plot:
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            a.error("--plot needs matplotlib (Debian: python3-matplotlib, e.g. run /usr/bin/python3)")
    if args.report:
        if not args.csv or not pathlib.Path(args.csv).exists():
            a.error("--report needs --csv with an earlier run's file")
        rows = read_rows(args.csv, key)
        print(markdown(rows, key))
        if args.plot:
            plot(rows, key, args.plot)
        return
    if not pathlib.Path(args.fesd).exists():
        a.error(f"no fesd binary at {args.fesd} (build it or pass --fesd)")
    rows = []
    if args.resume:
        if not args.csv:
            a.error("--resume needs --csv")
        # Points that ended without a result (timeout, a non-zero exit without JSON) are run
        # again, and their rows dropped from the file.
        rows = [r for r in read_rows(args.csv, key) if "objective" in r]
    done = {(r["form"], r["value"]) for r in rows}
    writer = None
    if args.csv:
        # The kept rows go to a new file that then replaces the old one (a run stopped here
        # loses nothing); the new points are appended to it as they finish.
        tmp = pathlib.Path(args.csv + ".tmp")
        with open(tmp, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=FIELDS)
            w.writeheader()
            for r in rows:
                w.writerow({k: r[k] for k in FIELDS if k in r})
        os.replace(tmp, args.csv)
        csv_file = open(args.csv, "a", newline="")
        writer = csv.DictWriter(csv_file, fieldnames=FIELDS)
    print("%-8s %4s %-24s %12s %9s %5s %6s %9s %8s" % ("form", key[:4], "status", "objective",
          "comp", "NLPs", "iter", "CPU s", "s/iter"), flush=True)
    if args.keep:
        pathlib.Path(args.keep).mkdir(parents=True, exist_ok=True)
    with contextlib.nullcontext(args.keep) if args.keep else tempfile.TemporaryDirectory() \
            as directory:
        for value in points:
            for form in forms:
                if (form, value) in done:
                    continue
                r = run_point(args.fesd, form, key, value, flags, no_guess[form], args.timeout,
                              directory, bool(args.keep))
                rows.append(r)
                print("%-8s %4d %-24s %12s %9s %5s %6s %9s %8s" % (
                    form, value, r["status"], "%.6g" % r["objective"] if "objective" in r else "-",
                    "%.1e" % r["comp_residual"] if "comp_residual" in r else "-",
                    r.get("nlps", "-"), r.get("ipopt_iterations", "-"), r.get("cpu_nlp_s", "-"),
                    r.get("cpu_per_iteration_s", "-")), flush=True)
                if writer:
                    writer.writerow(r)
                    csv_file.flush()
    if writer:
        csv_file.close()
    if args.plot:
        plot(rows, key, args.plot)


if __name__ == "__main__":
    main()
