"""The methods: one plain function per method, collected by :mod:`~signorini.solvers.registry`.

Each backend module (``pdas``, ``nested``, ``condensed``, ``uzawa``, ``qp``, ``cvxpy_``,
``petsc_``) lists its methods in ``METHODS`` and never imports the registry;
:mod:`~signorini.solvers.base` holds :class:`Method` and the judging of a claim of success
by the KKT certificate.
"""

from signorini.solvers.base import Method
from signorini.solvers.registry import REGISTRY, get_method, methods, register

__all__ = ["Method", "REGISTRY", "get_method", "methods", "register"]
