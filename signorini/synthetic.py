"""Small random contact QPs with known structure, for tests and teaching."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .problem import ContactProblem


def random_problem(n: int = 8, m: int = 3, seed: int = 0, condition: float = 10.0,
                   push: float = 1.0) -> ContactProblem:
    """A random SPD contact QP ``min ½uᵀKu − fᵀu  s.t.  Nu ≤ d``.

    ``K = QΛQᵀ`` with eigenvalues spread over ``[1, condition]``; each of the
    ``m`` rows of N has ``−1`` on its own dof (so N has full row rank) and a
    small random coupling to one other dof; ``f`` pushes the body towards the
    obstacle with strength ``push`` so that some but usually not all
    constraints are active.
    """
    if not 1 <= m <= n:
        raise ValueError(f"need 1 ≤ m ≤ n, got m={m}, n={n}")
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    eig = np.geomspace(1.0, condition, n)
    K = (q * eig) @ q.T
    K = 0.5 * (K + K.T)
    rows, cols, vals = [], [], []
    own = rng.permutation(n)[:m]
    for i, j in enumerate(own):
        rows.append(i), cols.append(j), vals.append(-1.0)
        other = int(rng.integers(n))
        if other != j:
            rows.append(i), cols.append(other), vals.append(0.2 * rng.standard_normal())
    N = sp.csr_matrix((vals, (rows, cols)), shape=(m, n))
    u_free_fall = -push * np.abs(rng.standard_normal(n))
    f = K @ u_free_fall
    d = np.abs(N @ u_free_fall) * rng.uniform(0.0, 1.5, m)
    return ContactProblem(
        K=sp.csr_matrix(K), f=f, N=N, d=d, weights=np.ones(m),
        contact_points=np.column_stack([np.arange(m, dtype=float), np.zeros(m)]),
        free_dofs=np.arange(n), prescribed=np.zeros(n), scene="random",
        params={"n": n, "m": m, "seed": seed, "condition": condition})
