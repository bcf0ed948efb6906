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

from signorini.numerics.active_set import ActiveSetSolver, PinnedFactor
from signorini.numerics.factor import available_backends, factorize
from signorini.numerics.lcp import delassus, delassus_max_eigenvalue, solve_lcp
from signorini.numerics.push import push_for_load
from signorini.numerics.multigrid import PyamgHierarchy, pinned_cg
from signorini.numerics.zone import Zone, ZoneSolver, predict_zone

__all__ = ["ActiveSetSolver", "PinnedFactor", "PyamgHierarchy", "Zone", "ZoneSolver",
           "available_backends", "delassus", "delassus_max_eigenvalue", "factorize", "pinned_cg",
           "predict_zone", "push_for_load", "solve_lcp"]
