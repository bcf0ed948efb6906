"""Numerical kernels that know nothing of meshes or scenes.

- :mod:`~signorini.numerics.factor`: sparse Cholesky/LU backends behind one interface
  (PARDISO, CHOLMOD, SuperLU);
- :mod:`~signorini.numerics.active_set`: pinned factorisations and the active-set systems on
  them;
- :mod:`~signorini.numerics.lcp`: the Delassus operator ``W = N K⁻¹ Nᵀ``, the dense
  linear complementarity problem on it, power iteration for ``λ_max(W)``;
- :mod:`~signorini.numerics.zone`: exact contact around a predicted contact zone on one
  factorisation (the kernel of the ``nested`` method and of large load targeting);
- :mod:`~signorini.numerics.push`: the push that gives a target contact force.
- :mod:`~signorini.numerics.multigrid`: algebraic multigrid (pyamg) and CG with pinned dofs,
  the linear algebra of ``pdas-amg``.
"""

import lazy_loader

# loaded at first use (lazy_loader): a module of the folder imports only what it needs
__getattr__, __dir__, _ = lazy_loader.attach(__name__, submod_attrs={
    "active_set": ["ActiveSetSolver", "PinnedFactor"], "factor": ["available_backends", "factorize"],
    "lcp": ["delassus", "delassus_max_eigenvalue", "solve_lcp"], "push": ["push_for_load"],
    "multigrid": ["PyamgHierarchy", "pinned_cg"], "zone": ["Zone", "ZoneSolver", "predict_zone"]})

__all__ = ["ActiveSetSolver", "PinnedFactor", "PyamgHierarchy", "Zone", "ZoneSolver",
           "available_backends", "delassus", "delassus_max_eigenvalue", "factorize", "pinned_cg",
           "predict_zone", "push_for_load", "solve_lcp"]
