"""Many independent simulations or OCP solves in parallel on Dask (python3-distributed).

    >>> import fesd.batch
    >>> guesses = [{"x0": [g]} for g in numpy.linspace(-3, 3, 30)]
    >>> results = fesd.batch.map("examples/ocp_sensitivity.toml", overrides=guesses)
    >>> [r.x0[0] for r in results]

The problem is read once here (bad input raises fesd.InputError before anything is sent); a
fesd.Problem pickles as its text and overrides, so the workers need fesd but not the file.
"""

import os
import shutil
import sys
import tempfile

from . import load, simulate, solve, InputError


class CaseError:
    """The outcome of a case that raised instead of returning a result (bad overrides, say).

    Attributes: status ("input_error" for fesd.InputError, "error" otherwise), message (the
    exception's message), exception (its type name), success (False), overrides (the case's).
    Picklable like the results, and in the same place of the list.
    """

    def __init__(self, status, message, exception, overrides):
        self.status = status
        self.message = message
        self.exception = exception
        self.overrides = overrides
        self.success = False

    def brief_report(self):
        """One line: the status and the message."""
        return f"{self.status}: {self.message}"

    def full_report(self):
        """The same as brief_report()."""
        return self.brief_report() + "\n"

    def __repr__(self):
        return f"<fesd.batch.CaseError {self.brief_report()}>"


def _run_case(problem, overrides):
    """One case on a worker: the problem (unpickled: read again from its text), with overrides."""
    try:
        run = solve if problem.kind == "ocp" else simulate
        return run(problem, options=overrides)
    except InputError as e:
        return CaseError("input_error", str(e), "InputError", overrides)
    except Exception as e:  # noqa: BLE001 - one failing case never stops the others
        return CaseError("error", str(e), type(e).__name__, overrides)


def _progress(done, total, out):
    width = 30
    filled = width * done // total if total else width
    out.write(f"\rfesd.batch: [{'#' * filled}{'.' * (width - filled)}] {done}/{total}")
    if done == total:
        out.write("\n")
    out.flush()


def map(problem, overrides, client=None, progress=True, n_workers=None):  # noqa: A001
    """Runs one simulation (or OCP solve) per entry of ``overrides``, in parallel on Dask.

    ``problem``: a fesd.Problem, a problem file's path or a dict (fesd.load); it is read and
    checked here.
    ``overrides``: a list of dicts, one per case, each as the keyword arguments of
    fesd.simulate / fesd.solve (``{"n_s": 3, "x0": [0.5]}``; dotted keys allowed).
    ``client``: None for a local cluster started for this call (``n_workers`` processes, default
    one per core, one thread each) and closed after it; a scheduler address
    ("tcp://host:8786") for an existing cluster; or a dask.distributed.Client.
    ``progress``: a progress bar on standard error while the cases run.

    Returns the results in the order of ``overrides``: SimulationResult or OcpResult (a case
    that does not converge has its status, as with fesd.simulate), or a CaseError for a case
    that raised (an override out of range, say): one failing case never stops the others.
    Dask's scratch and spill space go to a temporary directory, removed afterwards; nothing is
    written into the working directory.
    """
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError as e:
        raise ImportError("fesd.batch needs Dask's distributed scheduler (Debian: "
                          "python3-dask python3-distributed)") from e
    cases = [dict(o) for o in overrides]
    problem = load(problem)  # bad input raises here, before any worker starts

    scratch = None
    cluster = None
    own_client = None
    try:
        if client is None:
            scratch = tempfile.mkdtemp(prefix="fesd-dask-")
            cluster = LocalCluster(n_workers=n_workers or os.cpu_count() or 1,
                                   threads_per_worker=1, processes=True,
                                   local_directory=scratch, dashboard_address=None)
            client = own_client = Client(cluster)
        elif isinstance(client, str):
            client = own_client = Client(client)
        futures = [client.submit(_run_case, problem, case, pure=False) for case in cases]
        out = sys.stderr
        if progress:
            _progress(0, len(futures), out)
        done = 0
        for _ in as_completed(futures):
            done += 1
            if progress:
                _progress(done, len(futures), out)
        return [f.result() for f in futures]
    finally:
        if own_client is not None:
            own_client.close()
        if cluster is not None:
            cluster.close()
        if scratch is not None:
            shutil.rmtree(scratch, ignore_errors=True)


__all__ = ["map", "CaseError"]
