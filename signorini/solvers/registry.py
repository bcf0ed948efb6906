"""The method registry: every solver is a plain function with one signature.

``solve(problem, *, tol=None, max_iter=None, **options) -> ContactSolution``

``tol=None`` means the method's own default tolerance (for QP backends: the
backend's defaults, untouched). Unknown options raise :class:`InputError`.
"""

from __future__ import annotations

import importlib.util
import logging
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..errors import BackendNotInstalled, InputError
from ..problem import ContactProblem, ContactSolution

log = logging.getLogger(__name__)

SolverFunction = Callable[..., ContactSolution]

#: a claim of success is accepted when every relative KKT residual is at most
#: ``ACCEPT_FACTOR × tol`` (or ``DEFAULT_ACCEPT`` when no tolerance was asked for):
#: success means what qpbenchmark means by it, the residuals under the tolerance
ACCEPT_FACTOR = 1.0
DEFAULT_ACCEPT = 1e-6


@dataclass(frozen=True)
class Method:
    """A registered method.

    ``requires`` lists the Python modules it imports; ``extra`` is the
    pip extra that installs them. ``dense`` methods build dense matrices and
    refuse problems above ``max_dense_dofs``. ``exact`` methods reach the
    answer up to round-off when they converge.
    """

    name: str
    function: SolverFunction
    summary: str
    requires: tuple[str, ...] = ()
    extra: str = ""
    dense: bool = False
    exact: bool = False
    family: str = ""
    default_tol: float | None = None
    options: tuple[str, ...] = field(default=())

    @property
    def installed(self) -> bool:
        return all(importlib.util.find_spec(mod) is not None for mod in self.requires)


REGISTRY: dict[str, Method] = {}


def register(method: Method) -> Method:
    """Add a method to the registry (a later registration of a name replaces it)."""
    REGISTRY[method.name] = method
    return method


def get_method(name: str) -> Method:
    """Look a method up by name; unknown names list the known ones."""
    _load_builtin()
    if name in REGISTRY:
        return REGISTRY[name]
    if ":" in name:
        return _load_user_method(name)
    known = ", ".join(sorted(REGISTRY))
    raise InputError(f"unknown method {name!r}: choose --method from {known}")


def methods(installed_only: bool = False) -> list[Method]:
    """Every registered method, sorted by name."""
    _load_builtin()
    out = sorted(REGISTRY.values(), key=lambda m: m.name)
    return [m for m in out if m.installed] if installed_only else out


def _load_user_method(spec: str) -> Method:
    """``module:function`` or ``path/to/file.py:function``: a user solver with the standard signature.

    A module is looked up on ``sys.path`` and then in the current directory.
    """
    module_name, _, attr = spec.rpartition(":")
    try:
        if module_name.endswith(".py"):
            path = Path(module_name)
            if not path.is_file():
                raise ImportError(f"no file {module_name}")
            loader_spec = importlib.util.spec_from_file_location(path.stem, path)
            module = importlib.util.module_from_spec(loader_spec)
            loader_spec.loader.exec_module(module)
        else:
            if os.getcwd() not in sys.path:
                sys.path.append(os.getcwd())
            module = importlib.import_module(module_name)
    except ImportError as exc:
        raise InputError(f"method {spec!r}: cannot import module {module_name!r} ({exc}); "
                         "give --method module:function or path/to/file.py:function") from exc
    func = getattr(module, attr, None)
    if not callable(func):
        raise InputError(f"method {spec!r}: module {module_name!r} has no function {attr!r}")
    return Method(name=spec, function=func, summary=(func.__doc__ or "").strip().split("\n")[0],
                  family="user")


_BUILTIN_LOADED = False


def _load_builtin() -> None:
    global _BUILTIN_LOADED
    if _BUILTIN_LOADED:
        return
    from . import condensed_dual, cvxpy_, nested, pdas, petsc_, qp, uzawa  # noqa: F401  (each registers itself)
    _BUILTIN_LOADED = True


def solve(problem: ContactProblem, method: str = "pdas", *, tol: float | None = None,
          max_iter: int | None = None, **options: Any) -> ContactSolution:
    """Solve ``problem`` with ``method`` and judge the answer with the KKT certificate.

    The method's own claim of success becomes ``converged`` only when every
    relative residual of :func:`signorini.kkt.certificate` is within
    ``ACCEPT_FACTOR × tol``; otherwise the status is ``inaccurate`` and the
    message says by how much it missed. A backend exception becomes a
    ``failed`` solution; bad input (unknown options, non-positive tolerances)
    raises :class:`InputError`.
    """
    spec = get_method(method)
    if not spec.installed:
        missing = [m for m in spec.requires if importlib.util.find_spec(m) is None]
        raise BackendNotInstalled(
            f"method {method!r} needs {', '.join(missing)}: "
            f"pip install 'signorini[{spec.extra or 'all'}]'")
    tol = _check_tol(tol)
    max_iter = _check_max_iter(max_iter)
    start = time.perf_counter()
    try:
        solution = spec.function(problem, tol=tol, max_iter=max_iter, **options)
    except InputError:
        raise
    except Exception as exc:  # a backend's own error (e.g. CHOLMOD on a singular K) is a failed run
        log.warning("method %s raised %s: %s", method, type(exc).__name__, exc)
        solution = ContactSolution.failure(
            method, problem, "failed", f"{type(exc).__name__}: {exc}",
            solve_time=time.perf_counter() - start)
    # the method's own wall time; judging below (the certificate factorises K) is not the method's
    solution.extras["method_s"] = time.perf_counter() - start
    solution.method = method
    return judge(problem, solution, tol if tol is not None else spec.default_tol)


def _check_tol(tol: Any) -> float | None:
    if tol is None:
        return None
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.floating, np.integer)) \
            or not (np.isfinite(tol) and 0 < tol < 1):
        raise InputError(f"tol must be a number in (0, 1), got {tol!r}: e.g. tol=1e-9")
    return float(tol)


def _check_max_iter(max_iter: Any) -> int | None:
    if max_iter is None:
        return None
    ok = isinstance(max_iter, (int, np.integer)) and not isinstance(max_iter, bool)
    ok = ok or (isinstance(max_iter, (float, np.floating)) and np.isfinite(max_iter)
                and float(max_iter).is_integer())
    if not ok or max_iter < 1:
        raise InputError(f"max_iter must be a positive integer, got {max_iter!r}")
    return int(max_iter)


def judge(problem: ContactProblem, solution: ContactSolution,
          tol: float | None) -> ContactSolution:
    """Downgrade a claim of convergence that the certificate does not back."""
    from ..kkt import certificate

    if solution.status != "converged":
        return solution
    accept = ACCEPT_FACTOR * tol if tol is not None else DEFAULT_ACCEPT
    try:
        cert = certificate(problem, solution)
    except np.linalg.LinAlgError:  # K singular: no dual function; judge on the other residuals
        cert = certificate(problem, solution, duality_gap=False)
    worst_name, worst = cert.worst()
    if not np.isfinite(worst) or worst > accept:
        solution.extras["claimed_status"] = "converged"
        solution.status = "inaccurate"
        solution.message = (
            f"{solution.message}; the method claimed success but the KKT certificate's "
            f"{worst_name} residual is {worst:.1e} > {accept:.0e}: tighten the tolerance "
            "or use an exact method (pdas)").lstrip("; ")
    return solution
