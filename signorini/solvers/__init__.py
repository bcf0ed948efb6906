"""The methods: one plain function per method, collected by :mod:`~signorini.solvers.registry`.

Each backend module (``pdas``, ``nested``, ``condensed``, ``uzawa``, ``qp``, ``cvxpy_``,
``petsc_``) lists its methods in ``METHODS`` and never imports the registry;
:mod:`~signorini.solvers.base` holds :class:`Method` and the judging of a claim of success
by the KKT certificate.

Its names load the registry (every backend module) at first use, so that a command reading
:mod:`~signorini.solvers.options` (the options and the table of default tolerances) imports no method.
"""

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from signorini.solvers.base import Method
    from signorini.solvers.registry import REGISTRY, get_method, methods


def __getattr__(name: str) -> Any:
    """``Method`` from :mod:`~signorini.solvers.base`, the rest from the registry, at first use."""
    if name not in __all__:
        raise AttributeError(f"module 'signorini.solvers' has no attribute {name!r}")
    home = "signorini.solvers.base" if name == "Method" else "signorini.solvers.registry"
    return getattr(importlib.import_module(home), name)


__all__ = ["Method", "REGISTRY", "get_method", "methods"]
