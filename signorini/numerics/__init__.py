"""Numerical kernels that know nothing of meshes or scenes.

- :mod:`~signorini.numerics.factor`: sparse Cholesky/LU backends behind one interface
  (PARDISO, CHOLMOD, SuperLU), pinned factorisations and active-set systems;
- :mod:`~signorini.numerics.lcp`: the Delassus operator ``W = N K⁻¹ Nᵀ``, the dense
  linear complementarity problem on it, power iteration for ``λ_max(W)``;
- :mod:`~signorini.numerics.zone`: exact contact around a predicted contact zone on one
  factorisation (the kernel of the ``nested`` method and of large load targeting);
- :mod:`~signorini.numerics.loading`: the push that gives a target contact force.
- :mod:`~signorini.numerics.multigrid`: algebraic multigrid (pyamg) and CG with pinned dofs,
  the linear algebra of ``pdas-amg``.
"""
