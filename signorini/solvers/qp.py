"""The contact QP through qpsolvers: one method ``qp-<backend>`` per backend.

``min ½uᵀKu − fᵀu  s.t.  Nu ≤ d`` is handed to :func:`qpsolvers.solve_problem` in the
formulation of the option ``form`` (:mod:`signorini.solvers.forms`). qpsolvers' multiplier
``z`` of ``Gx ≤ h`` is non-negative and satisfies ``Px + q + Gᵀz = 0``, our
``K u − f + Nᵀλ = 0`` with ``λ = z``: no sign change.

Every backend is one row of :data:`signorini.solvers.qp_backends.BACKENDS`; the methods are
registered by one loop at the bottom of the module. A backend that prints from C whatever its
verbosity runs with the process's output sent nowhere (:func:`c_output_discarded`): the
library never prints.
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import importlib.util
import os
import sys
import time
from typing import Any

import numpy as np

from signorini.errors import BackendNotInstalled, InputError, SolverError, install_hint
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.solvers import forms
from signorini.solvers.base import Method
from signorini.solvers.options import checked
from signorini.solvers.qp_backends import (BACKEND_BY_NAME, BACKENDS, COMMON_TYPES,
                                           DEFAULT_MAX_DENSE_DOFS, FAILED, MAX_ITER, Backend)

__all__ = ["METHODS", "solve_qp"]


@contextlib.contextmanager
def c_output_discarded():
    """The process's stdout and stderr sent nowhere, at the file descriptors and in Python: for
    backends that print whatever their verbosity, from C or through Python's ``sys.stdout``
    (HiGHS's banner; OSQP's "Polishing not needed")."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    sink = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(sink, 1)
        os.dup2(sink, 2)
        with open(os.devnull, "w") as nowhere, contextlib.redirect_stdout(nowhere), \
                contextlib.redirect_stderr(nowhere):
            yield
    finally:
        ctypes.CDLL(None).fflush(None)  # what C buffered goes where it was meant to: nowhere
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in saved + [sink]:
            os.close(fd)


@functools.cache
def silence_highs_banner() -> None:
    """HiGHS prints its banner from C on the first ``Highs()`` of a process, whatever the
    options (highspy 1.16): make that first one with the process's output sent nowhere."""
    import highspy

    with c_output_discarded():
        highspy.Highs()


def solve_qp(problem: ContactProblem, backend: str, *, tol: float | None = None,
             max_iter: int | None = None, **options: Any) -> ContactSolution:
    """Solve ``min ½uᵀKu − fᵀu  s.t.  Nu ≤ d`` with the qpsolvers ``backend`` (``"osqp"``…).

    ``tol`` (the relative KKT tolerance) and ``max_iter`` are translated into the backend's own
    options (None: its defaults); the backend's ``options`` pass through after them, so they
    win. ``max_dense_dofs`` (default 3000) caps ``n`` for dense backends and ``m`` for the dual
    form; ``form`` and ``polish`` default to the backend's (:mod:`signorini.solvers.forms`).
    The answer: ``u = x``, ``λ = z``; ``extras["raw_status"]`` is the backend's own word.
    InputError for a bad option or a problem too large for a dense backend;
    BackendNotInstalled when qpsolvers cannot load it; SolverError (``from`` the backend's
    exception) when it raises.
    """
    spec = BACKEND_BY_NAME[backend]
    options = checked(spec.method_name, options, spec.typed_options)
    max_dense_dofs = options.get("max_dense_dofs", DEFAULT_MAX_DENSE_DOFS)
    form, note = forms.resolve(spec.method_name, problem, options.get("form"), spec.form,
                               max_dense_dofs)
    polishing = spec.polish if options.get("polish") is None else options["polish"]
    dense_n = spec.dense and problem.n > max_dense_dofs
    if form != "dual" and dense_n:
        raise InputError(
            f"method {spec.method_name!r} builds dense n × n matrices and n = {problem.n} "
            f"exceeds max_dense_dofs = {max_dense_dofs}: pick a sparse backend or raise "
            "the option max_dense_dofs")
    import qpsolvers  # optional backend: only when a qp-* method runs

    if spec.name not in qpsolvers.available_solvers:
        missing = [m for m in spec.modules if importlib.util.find_spec(m) is None]
        raise BackendNotInstalled(
            f"qpsolvers cannot load backend {spec.name!r} (missing: {', '.join(missing) or '?'}; "
            f"available: {', '.join(qpsolvers.available_solvers)}): "
            f"{install_hint(spec.extra, missing)}")
    settings = {**spec.settings(tol, max_iter), **spec.fixed,
                **{k: v for k, v in options.items() if k not in COMMON_TYPES}}
    if spec.nest is not None:
        settings = spec.nest(settings)

    start = time.perf_counter()
    fallback = options.get("form") is None and not dense_n  # the default form may fall back
    data = forms.formulate(problem, form, spec.dense, fallback=fallback)
    qp = (qpsolvers.Problem(data.P, data.q, lb=np.zeros(problem.m)) if data.bounds
          else qpsolvers.Problem(data.P, data.q, data.G, data.h))
    build_time = time.perf_counter() - start
    if spec.name == "highs":
        silence_highs_banner()
    quiet = c_output_discarded() if spec.prints else contextlib.nullcontext()
    try:
        with forms.warned(spec.label) as caught, quiet:
            result = (qpsolvers.solve_problem(qp, spec.name, verbose=False, **settings)
                      if spec.call is None else spec.call(qp, **settings))
    except qpsolvers.ParamError as exc:
        raise InputError(f"{spec.label}: bad option: {exc}") from exc
    except Exception as exc:
        passed = {k: v for k, v in options.items() if k not in COMMON_TYPES}
        hint = f" (with the options {passed})" if passed else ""
        raise SolverError(f"{spec.label} raised {type(exc).__name__}: {exc}{hint}") from exc
    elapsed = time.perf_counter() - start - build_time

    report = spec.read(result, caught)
    status = spec.status(report.raw_status)
    if (status == FAILED and max_iter is not None and report.iterations is not None
            and report.iterations >= max_iter):
        status = MAX_ITER  # e.g. CVXOPT says "unknown" when it runs out of iterations
    if result.build_time is not None and result.solve_time is not None:
        build_time += result.build_time
        elapsed = result.solve_time
    extras = {"raw_status": report.raw_status, "backend": spec.name, "backend_warnings": caught,
              **report.details}
    return forms.solution_from(problem, data, spec.method_name, status, result.x, result.z,
                               said_by=f"{spec.label}: {report.raw_status}", extras=extras,
                               note=note, iterations=report.iterations, build_time=build_time,
                               solve_time=elapsed, tol=tol, polishing=polishing)


METHODS = tuple(
    Method(name=backend.method_name, function=functools.partial(solve_qp, backend=backend.name),
           summary=backend.summary, requires=("qpsolvers", *backend.modules),
           extra=backend.extra, dense=backend.dense, exact=False, family="qp",
           typed_options=backend.typed_options)
    for backend in BACKENDS)
