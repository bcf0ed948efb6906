"""Sparse factorisation of the SPD stiffness: factorise once, solve many right-hand sides."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


class Factor:
    """``K⁻¹`` applied by a sparse LU of ``K`` (SciPy's SuperLU, symmetric mode).

    ``solve(b)`` takes a vector or an (n, k) array of right-hand sides.
    """

    def __init__(self, K: sp.spmatrix):
        K = sp.csc_matrix(K)
        self.shape = K.shape
        self._lu = spla.splu(K, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                             options={"SymmetricMode": True})

    def solve(self, b: np.ndarray) -> np.ndarray:
        b = np.asarray(b, dtype=float)
        return self._lu.solve(b)


def factorize(K: sp.spmatrix) -> Factor:
    """Factorise the SPD matrix ``K`` once for repeated solves."""
    return Factor(K)
