"""The methods: one plain function per method, collected by :mod:`~signorini.solvers.registry`.

Each backend module (``pdas``, ``nested``, ``condensed``, ``uzawa``, ``qp``, ``cvxpy_``,
``petsc_``) lists its methods in ``METHODS`` and never imports the registry;
:mod:`~signorini.solvers.base` holds :class:`Method` and the judging of a claim of success
by the KKT certificate.
"""

import lazy_loader

# loaded at first use (lazy_loader): a command reading solvers.options (the options and the
# table of default tolerances) imports no method
__getattr__, __dir__, _ = lazy_loader.attach(__name__, submod_attrs={
    "base": ["Method"], "registry": ["REGISTRY", "get_method", "methods"]})

__all__ = ["Method", "REGISTRY", "get_method", "methods"]
