"""signorini: frictionless contact of an elastic body with a rigid obstacle, as one QP.

The public API (see the README's "Python" section)::

    import signorini
    result = signorini.solve("hertz-cylinder", params={"E": 2.1e11, "R": 0.01})
    result.status, result.total_force, result.pressure, result.hertz

:func:`solve` takes a scene name or a :class:`ContactProblem` (from
:func:`build_problem`, :meth:`ContactProblem.from_qp` or
:meth:`ContactProblem.load`) and returns a :class:`Result` in the problem's
own units; :func:`certificate` judges any answer; :func:`derivative`
differentiates an output with respect to a scene parameter; :func:`crosscheck` solves one
problem with several methods and compares every pair; :func:`methods` and
:func:`scene_families` list what there is; :func:`with_load` moves a built scene's target
load on its mesh and K (a load slider).

The names are loaded when first used (module ``__getattr__``): ``import signorini``
costs nothing beyond the package itself, and a command imports only what it uses.
"""

import importlib
import logging
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # what the names below are, for readers and type checkers
    from signorini.api import (DEFAULT_METHOD, Result, at_load, build_problem, certificate, methods,
                               scene_families, solve, solve_adaptive, with_load)
    from signorini.crosschecking import CrossCheck, crosscheck
    from signorini.errors import BackendNotInstalled, InputError, SignoriniError, SolverError
    from signorini.certification.kkt import Certificate
    from signorini.problem.contact import ContactProblem, ContactSolution, Discretisation, Scales
    from signorini.derivatives.scene import derivative
    from signorini.problem.solution import WarmStart
    from signorini.solvers.base import DEFAULT_TOL

#: the module each public name lives in, imported at the name's first use
_HOMES = {
    **dict.fromkeys(("DEFAULT_METHOD", "Result", "at_load", "build_problem", "certificate", "methods",
                     "scene_families", "solve", "solve_adaptive", "with_load"), "signorini.api"),
    **dict.fromkeys(("CrossCheck", "crosscheck"), "signorini.crosschecking"),
    **dict.fromkeys(("BackendNotInstalled", "InputError", "SignoriniError", "SolverError"),
                    "signorini.errors"),
    **dict.fromkeys(("ContactProblem", "ContactSolution", "Discretisation", "Scales"),
                    "signorini.problem.contact"),
    "Certificate": "signorini.certification.kkt", "derivative": "signorini.derivatives.scene",
    "WarmStart": "signorini.problem.solution", "DEFAULT_TOL": "signorini.solvers.base",
}

__version__ = "0.1.0"

logging.getLogger(__name__).addHandler(logging.NullHandler())


def __getattr__(name: str) -> Any:
    """A public name, imported from its module at first use (then kept here)."""
    if name not in _HOMES:
        raise AttributeError(f"module 'signorini' has no attribute {name!r}")
    value = getattr(importlib.import_module(_HOMES[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


__all__ = ["DEFAULT_METHOD", "DEFAULT_TOL", "BackendNotInstalled", "Certificate", "ContactProblem",
           "ContactSolution", "CrossCheck", "Discretisation", "InputError", "Result", "Scales",
           "SignoriniError", "SolverError", "WarmStart", "__version__", "at_load", "build_problem",
           "certificate", "crosscheck", "derivative", "methods", "scene_families", "solve", "solve_adaptive",
           "with_load"]
