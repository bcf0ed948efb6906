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
:func:`scene_families` list what there is.
"""

import logging

from signorini.api import (
    DEFAULT_METHOD,
    Result,
    at_load,
    build_problem,
    certificate,
    methods,
    scene_families,
    solve,
    solve_adaptive,
)
from signorini.crosschecking import CrossCheck, crosscheck
from signorini.scene_derivatives import derivative
from signorini.errors import BackendNotInstalled, InputError, SignoriniError, SolverError
from signorini.kkt import Certificate
from signorini.problem import ContactProblem, ContactSolution, Discretisation, Scales
from signorini.solution import WarmStart
from signorini.solvers.base import DEFAULT_TOL

__version__ = "0.1.0"

logging.getLogger(__name__).addHandler(logging.NullHandler())

__all__ = ["DEFAULT_METHOD", "DEFAULT_TOL", "BackendNotInstalled", "Certificate", "ContactProblem",
           "ContactSolution", "CrossCheck", "Discretisation", "InputError", "Result", "Scales",
           "SignoriniError", "SolverError", "WarmStart", "__version__", "at_load", "build_problem",
           "certificate", "crosscheck", "derivative", "methods", "scene_families", "solve", "solve_adaptive"]
