"""fesd: Finite Elements with Switch Detection for nonsmooth ODEs, from Python.

Simulate piecewise smooth (Filippov) systems and solve optimal control problems with the FESD
method (exact switch detection, high-order accuracy, correct sensitivities). Problems are the
TOML problem files of the ``fesd`` program (docs/problem-files.md), or Python dicts of the same
structure; expressions are strings, so derivatives stay exact and solves run without the GIL.

    >>> import fesd
    >>> r = fesd.simulate("examples/oscillator.toml", n_s=3, N_sim=40)
    >>> r.status, r.x[-1], r.switch_times
    ('success', array([-1.59746038, -0.76149362]), array([1.]))
    >>> ocp = fesd.solve("examples/ocp_sensitivity.toml")
    >>> ocp.objective
    1.5237727...

Functions: load, simulate, solve. Results: SimulationResult, OcpResult (numpy arrays, picklable).
Errors: InputError (a ValueError) for bad input; a solver that does not converge is a status.
"""

import math
import os
import json

from ._fesd import InputError, Problem
from . import _fesd

__all__ = ["load", "simulate", "solve", "to_toml", "Problem", "SimulationResult", "OcpResult",
           "InputError"]

InputError.__module__ = "fesd"
Problem.__module__ = "fesd"


# ---- dicts as TOML text ----------------------------------------------------------------------

def _toml_key(key):
    key = str(key)
    if key and all(ch.isalnum() or ch in "_-" for ch in key):
        return key
    return json.dumps(key, ensure_ascii=False)


def _toml_value(value, where):
    if hasattr(value, "tolist") and not isinstance(value, (str, bytes)):  # numpy arrays, scalars
        value = value.tolist()
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, dict):
        items = ", ".join(f"{_toml_key(k)} = {_toml_value(v, f'{where}.{k}')}"
                          for k, v in value.items())
        return "{ " + items + " }" if items else "{}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v, f"{where}[{i}]") for i, v in enumerate(value)) + "]"
    raise InputError(f"{where}: cannot be written to a problem file: {type(value).__name__} "
                     f"(use numbers, strings, booleans, lists and dicts)")


def to_toml(problem):
    """The TOML text of a problem given as a dict with a problem file's structure.

    Top-level scalars (``name``, ``description``) come first, then one ``[table]`` per dict
    value (``model``, ``simulation`` or ``ocp``, ``discretization``, ``homotopy``, ``ipopt``);
    dicts inside a table become inline tables (``p = { omega = 6.28 }``). Numbers, strings,
    booleans, lists (also numpy arrays) and dicts are accepted; inf and nan are written as TOML's
    ``inf`` and ``nan``. Raises InputError for anything else.
    """
    if not isinstance(problem, dict):
        raise InputError(f"a problem must be a dict (got {type(problem).__name__})")
    lines = []
    tables = []
    for key, value in problem.items():
        if isinstance(value, dict):
            tables.append((key, value))
        else:
            lines.append(f"{_toml_key(key)} = {_toml_value(value, str(key))}")
    for name, table in tables:
        lines.append("")
        lines.append(f"[{_toml_key(name)}]")
        for key, value in table.items():
            lines.append(f"{_toml_key(key)} = {_toml_value(value, f'{name}.{key}')}")
    return "\n".join(lines) + "\n"


# ---- problems --------------------------------------------------------------------------------

def load(source, name="<dict>", **tables):
    """Reads a problem: a simulation or an optimal control problem (OCP).

    ``source`` is one of
      * a path (str or os.PathLike) of a problem file (docs/problem-files.md);
      * a dict with a problem file's structure, e.g.
        ``{"model": {"x": ["x"], "c": ["x"], "F": [[-1], [1]], "x0": [1.0]},
        "simulation": {"T_sim": 2, "N_sim": 10}}``
        (an ``"ocp"`` key makes it an OCP); ``name`` is then used in error messages;
      * None, with the tables as keyword arguments: ``fesd.load(None, model={...},
        simulation={...})``;
      * a Problem (returned as it is).

    Returns a fesd.Problem (``kind`` is "simulation" or "ocp"). Raises InputError (a ValueError)
    with the fesd program's one-line message ("file.toml:12: unknown key 'n_S' (did you mean
    'n_s'?)") for a malformed file or dict, FileNotFoundError-like problems included.
    """
    if isinstance(source, Problem):
        if tables:
            raise InputError("load: table keyword arguments need source=None")
        return source
    if source is None:
        source = {}
    if isinstance(source, dict):
        merged = dict(source)
        merged.update(tables)
        model = merged.get("model")
        projected = isinstance(model, dict) and model.get("kind") == "projected"
        return _fesd._parse(to_toml(merged), str(name), "ocp" in merged, projected)
    if tables:
        raise InputError("load: table keyword arguments go with a dict or None, not a file")
    if isinstance(source, (str, os.PathLike)):
        return _fesd._load(os.fspath(source))
    raise InputError(f"load: expected a path, a dict or a fesd.Problem (got "
                     f"{type(source).__name__})")


def _override_text(key, value):
    if hasattr(value, "tolist") and not isinstance(value, (str, bytes)):
        value = value.tolist()
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, (list, tuple)):
        return ",".join(_override_text(key, v) for v in value)
    return str(value)


def _override_pairs(options, overrides):
    merged = {}
    if options:
        merged.update(options)
    merged.update(overrides)
    pairs = []
    for key, value in merged.items():
        if key == "p" and isinstance(value, dict):  # parameters by name
            pairs += [("p", f"{name}={_override_text(name, v)}") for name, v in value.items()]
        elif key == "ipopt" and isinstance(value, dict):  # any IPOPT option
            pairs += [(f"ipopt.{name}", _override_text(name, v)) for name, v in value.items()]
        else:
            pairs.append((str(key), _override_text(key, value)))
    return pairs


_OVERRIDES_DOC = """
    Overrides are keyword arguments, as on the fesd command line (``--n_s 3``): every key of the
    [simulation], [discretization], [homotopy] and [ipopt] tables (``n_s=3``, ``N_sim=40``,
    ``rk_scheme="gauss_legendre"``, ``use_fesd=False``, ``tol_sim=1e-8``), for an OCP also
    ``T``, ``N_stages``, ``N_FE``, ``initialization``, ...; ``x0=[1, 0]`` (a list or array),
    ``p={"omega": 6}`` (parameters by name), ``ipopt={"tol": 1e-10}`` (any IPOPT option).
    Keys that are not Python identifiers go into ``options``, a dict of the same form
    (``options={"ipopt.max_iter": 500}``). A problem given by path or dict is read first
    (see fesd.load). An unknown key or a bad value raises InputError naming it.
"""


def simulate(problem, options=None, **overrides):
    """Simulates a problem with a [simulation] table; returns a SimulationResult.

    ``problem``: a fesd.Problem, a file path or a dict (fesd.load). The number of steps is
    N_sim, or chosen for ``tol_sim``; the error of x(T) is estimated from companion runs
    (``result.accuracy``; ``error_estimate=False`` skips them).
""" + _OVERRIDES_DOC + """
    A step that does not converge is not an exception: ``result.status`` says so (e.g.
    "nlp_failed") and ``result.message`` why. The GIL is released while it runs, so threads
    can simulate in parallel.

    Example: ``fesd.simulate("examples/oscillator.toml", n_s=3, N_sim=40).x[-1]``
    """
    p = load(problem)
    pairs = _override_pairs(options, overrides)
    return _with_source(SimulationResult(_fesd._simulate(p, pairs)), p, pairs)


def solve(problem, options=None, **overrides):
    """Solves an optimal control problem (a problem with an [ocp] table); returns an OcpResult.

    ``problem``: a fesd.Problem, a file path or a dict (fesd.load). The OCP is discretized with
    FESD on every control interval and solved by the MPCC homotopy (IPOPT).
""" + _OVERRIDES_DOC + """
    A homotopy or NLP that fails is not an exception: ``result.status`` says so and
    ``result.message`` why. The GIL is released while it runs.

    Example: ``fesd.solve("examples/ocp_sensitivity.toml").objective``
    """
    p = load(problem)
    pairs = _override_pairs(options, overrides)
    return _with_source(OcpResult(_fesd._solve(p, pairs)), p, pairs)


def _with_source(result, problem, pairs):
    """Keeps the problem and overrides of a two-state result: its plot draws the switching
    surfaces, which need the model (computed only when plotted)."""
    if len(result.state_names) == 2:
        result._source = (problem, pairs)
    return result


def with_options(problem, options=None, **overrides):
    """A copy of ``problem`` (fesd.load accepts it) with the overrides applied (see simulate).

    Useful to check overrides before a long run, or to keep a modified problem:
    ``q = fesd.with_options("examples/oscillator.toml", n_s=2)``. Raises InputError.
    """
    return _fesd._with_overrides(load(problem), _override_pairs(options, overrides))


# ---- results ---------------------------------------------------------------------------------

class _Result:
    """Plain data (numpy arrays, lists, dicts, strings): picklable, comparable field by field."""

    _fields = ()

    def __init__(self, data):
        self.__dict__.update(data)

    def brief_report(self):
        """One line: status, final state (the objective for an OCP), switches, time."""
        return self.__dict__["_brief_report"]

    def full_report(self):
        """Several lines: as the fesd program prints after a run (switches, work, timing)."""
        return self.__dict__["_full_report"]

    def plot(self, path=None, title=None):
        """Draws the result with matplotlib (python3-matplotlib); returns the Figure.

        What the fesd program's --plot draws: the states over t with the switches as dashed
        lines labelled with the regions before and after ("{0}->{1}") and sliding shaded, the
        step sizes h_n, for an OCP the controls and eta_n; a phase portrait for two states.
        ``path``: also saved there (PNG, SVG, PDF by its suffix). See fesd.plot.plot.
        """
        from .plot import plot
        return plot(self, path, title)

    @property
    def success(self):
        """True if status is "success"."""
        return self.status == "success"

    def __repr__(self):
        return f"<fesd.{type(self).__name__} {self.brief_report().strip()}>"


def _result_init(self, data):
    data = dict(data)
    data["_brief_report"] = data.pop("brief_report")
    data["_full_report"] = data.pop("full_report")
    _Result.__init__(self, data)


class SimulationResult(_Result):
    """The result of fesd.simulate (the same data as the fesd program's --json output).

    Attributes (numpy arrays unless said otherwise; N elements, n_s stages each):
      status (str): "success", "complementarity_not_met", "nlp_failed", "evaluation_failed",
          "tolerance_not_met"; message (str): one sentence about it; success (bool).
      name (str), state_names (list of str), region_subsystem (list: the subsystem of each
          region).
      t (N+1,): element boundaries; x (N+1, n_x): states there; h (N,): element lengths;
      x_final (n_x,): x(T).
      t_stage (N n_s,), x_stage (N n_s, n_x), theta, lambda_ (N n_s, n_regions), mu (N n_s,
          n_subsystems): stage points and the algebraic variables there (``lambda`` is a Python
          keyword, hence ``lambda_``).
      active_set (list of lists): active regions (from 0) per element.
      switches (list of dict): t, element, before, after (regions), located; switch_times
          (array of their t).
      homotopy (list of lists of dict): per solve attempt the homotopy rows (k, sigma,
          comp_residual, objective, inf_pr, nlp_iterations, nlp_status, cpu_s, wall_s, ...); steps solved
          on the active-set path have none.
      summary (dict): work and time (homotopy_steps, nlp_iterations, wall_s, derivative_s,
          solver_s, setup_s, max_comp_residual, active_set_path_steps, newton_iterations, ...,
          warnings).
      accuracy (dict): error_estimate of x(T), switch_time_estimate, order, tol_sim, met,
          N_sim, note, runs (one dict per integration made).
      step_path (list of str): per integration step the path that solved it, "active_set" or
          "homotopy".
      sensitivities (dict): with ``sensitivities=True``, dx(T)/dx0 as ``x0`` (n_x, n_x), dx(T)/du
          as ``u`` (n_x, n_u), dx(T)/dp as ``p`` (n_x, n_p) (docs/sensitivities.md); ``available``
          (bool) and ``message`` (why not); empty arrays when not requested.
    Methods: brief_report(), full_report(), plot().
    """

    __init__ = _result_init


class OcpResult(_Result):
    """The result of fesd.solve (the same data as the fesd program's --json output).

    Attributes (numpy arrays unless said otherwise):
      status (str), message (str), success (bool), name (str), state_names, control_names.
      objective (float): the OCP's cost, without the MPCC penalty terms; comp_residual (float);
      mpcc_mode (str).
      t (M+1,): element boundaries of all control intervals; x (M+1, n_x); h (M,); interval
          (list of int): the control interval of each element; x0, x_final (n_x,).
      t_ctrl (N_stages+1,): the control grid; u (N_stages, n_u): the control of each interval.
      active_set, switches, switch_times: as in SimulationResult.
      eta (M,): eta of eq. (31) at each element's start (NaN at interval starts), 0 at a switch.
      t_stage, x_stage, theta, lambda_: stage points and values.
      homotopy (list of dict): one row per NLP solved; summary (dict): work and time.
    Methods: brief_report(), full_report(), plot().
    """

    __init__ = _result_init
