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

The names are loaded when first used (``lazy_loader``): ``import signorini``
costs nothing beyond the package itself, and a command imports only what it uses.
"""

import logging
from typing import TYPE_CHECKING

import lazy_loader

if TYPE_CHECKING:  # what the names below are, for readers and type checkers
    from signorini.api import (DEFAULT_METHOD, Result, at_load, certificate, methods, scene_families,
                               solve, solve_adaptive)
    from signorini.certification.kkt import Certificate
    from signorini.crosschecking import CrossCheck, crosscheck
    from signorini.derivatives.scene import derivative
    from signorini.errors import BackendNotInstalled, InputError, SignoriniError, SolverError
    from signorini.problem.contact import ContactProblem, ContactSolution, Model, Scales, WarmStart
    from signorini.scenes.build import build_problem, with_load
    from signorini.solvers.options import DEFAULT_TOL

__version__ = "0.1.0"

logging.getLogger(__name__).addHandler(logging.NullHandler())

# each public name is imported from its module at first use
__getattr__, _, _ = lazy_loader.attach(__name__, submod_attrs={
    "api": ["DEFAULT_METHOD", "Result", "at_load", "certificate", "methods", "scene_families",
            "solve", "solve_adaptive"],
    "certification.kkt": ["Certificate"],
    "crosschecking": ["CrossCheck", "crosscheck"],
    "derivatives.scene": ["derivative"],
    "errors": ["BackendNotInstalled", "InputError", "SignoriniError", "SolverError"],
    "problem.contact": ["ContactProblem", "ContactSolution", "Model", "Scales", "WarmStart"],
    "scenes.build": ["build_problem", "with_load"],
    "solvers.options": ["DEFAULT_TOL"]})

__all__ = ["DEFAULT_METHOD", "DEFAULT_TOL", "BackendNotInstalled", "Certificate", "ContactProblem",
           "ContactSolution", "CrossCheck", "InputError", "Model", "Result", "Scales",
           "SignoriniError", "SolverError", "WarmStart", "__version__", "at_load", "build_problem",
           "certificate", "crosscheck", "derivative", "methods", "scene_families", "solve",
           "solve_adaptive", "with_load"]


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
