"""Small random contact QPs with known structure, for the tests (and the two-wheel bogie)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from signorini.errors import InputError
from signorini.problem.contact import ContactProblem, Model


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
        contact_points=np.column_stack([np.arange(m, dtype=float), np.zeros(m)]), name="random")


def _beam_element_stiffness(length: float, bending_stiffness: float) -> np.ndarray:
    """Euler–Bernoulli beam element (cubic Hermite), dofs ``(w₁, θ₁, w₂, θ₂)``.

    ``k = EI/h³ [[12, 6h, −12, 6h], [6h, 4h², −6h, 2h²], [−12, −6h, 12, −6h], [6h, 2h², −6h, 4h²]]``.
    """
    h = length
    return bending_stiffness / h ** 3 * np.array([
        [12.0, 6.0 * h, -12.0, 6.0 * h],
        [6.0 * h, 4.0 * h * h, -6.0 * h, 2.0 * h * h],
        [-12.0, -6.0 * h, 12.0, -6.0 * h],
        [6.0 * h, 2.0 * h * h, -6.0 * h, 4.0 * h * h]])


def bogie(*, half_length: float = 1.0, bending_stiffness: float = 10.0,
          mount_stiffness: float = 1.0, tilt_stiffness: float = 0.25, lowering: float = 1.0,
          gaps: tuple[float, float] = (0.0, 0.3)) -> ContactProblem:
    """Two contact points: an elastic beam on a rubber mount, pressed onto an uneven rail.

    The frame of a two-wheel bogie is an Euler–Bernoulli beam of length ``2ℓ``
    (``ℓ = half_length``, bending stiffness ``EI``) with a wheel at each end.
    Its centre hangs from the vehicle through a rubber mount: a vertical spring
    ``k_v`` and a torsional spring ``k_θ``. The vehicle is lowered by ``δ``, which
    pulls the centre down with the force ``k_v δ``; the rail lies ``gᵢ`` below
    wheel ``i``. With deflections ``w`` positive upwards and the dofs
    ``u = (w₁, θ₁, w_c, θ_c, w₂, θ₂)`` (ends and centre, two cubic Hermite
    elements, exact for nodal loads)::

        minimise ½uᵀKu − fᵀu   subject to   −w₁ ≤ g₁,  −w₂ ≤ g₂

    with ``K`` the beam stiffness plus ``k_v`` on ``w_c`` and ``k_θ`` on ``θ_c``, and
    ``f = −k_v δ e_{w_c}``. The multiplier ``λᵢ ≥ 0`` is the load on wheel ``i``.

    The Delassus operator ``W = N K⁻¹ Nᵀ`` is the compliance of the wheels, in
    closed form::

        W₁₁ = W₂₂ = ℓ³/(3EI) + 1/k_v + ℓ²/k_θ,    W₁₂ = 1/k_v − ℓ²/k_θ.

    Pushing one wheel up lifts the centre (``1/k_v``) but tilts the frame, which
    pushes the other wheel down (``ℓ²/k_θ``): with a soft tilt (the default)
    ``W₁₂ < 0`` and the model behaves like a seesaw. That is what makes Uzawa's
    iteration blow up, not merely oscillate, beyond ``ρ = 2/λ_max(W)``: with
    ``W ≥ 0`` entrywise the projection onto ``λ ≥ 0`` keeps the iterates bounded.

    With the defaults both wheels touch (the dual maximiser lies inside the
    quadrant ``λ > 0``); with ``gaps=(0.0, 2.0)`` wheel 2 stays in the air and
    the maximiser lies on the axis ``λ₂ = 0``. Everything is dimensionless;
    ``weights`` are 1 (point contacts: the "pressure" is the force).

    Raises
    ------
    InputError
        A length or stiffness is not positive, or ``gaps`` does not hold two finite numbers.
    """
    for name, value in (("half_length", half_length), ("bending_stiffness", bending_stiffness),
                        ("mount_stiffness", mount_stiffness), ("tilt_stiffness", tilt_stiffness)):
        if not (np.isfinite(value) and value > 0):
            raise InputError(f"bogie: {name}={value!r} must be a positive number")
    gap = np.asarray(gaps, dtype=float)
    if gap.shape != (2,) or not np.all(np.isfinite(gap)):
        raise InputError(f"bogie: gaps={gaps!r} must be two finite numbers (g₁, g₂)")
    if not np.isfinite(lowering):
        raise InputError(f"bogie: lowering={lowering!r} must be a finite number")
    ell, k_v, k_t = float(half_length), float(mount_stiffness), float(tilt_stiffness)
    nodes = np.array([-ell, 0.0, ell])
    K = np.zeros((6, 6))
    for e in range(2):
        dofs = np.arange(2 * e, 2 * e + 4)
        K[np.ix_(dofs, dofs)] += _beam_element_stiffness(ell, bending_stiffness)
    K[2, 2] += k_v
    K[3, 3] += k_t
    f = np.zeros(6)
    f[2] = -k_v * lowering
    N = sp.csr_matrix(([-1.0, -1.0], ([0, 1], [0, 4])), shape=(2, 6))
    load_row = np.zeros(6)
    load_row[2] = k_v  # mount force on the frame: k_v (δ + w_c), carried by the wheels
    return ContactProblem(
        K=sp.csr_matrix(K), f=f, N=N, d=gap, weights=np.ones(2),
        contact_points=np.column_stack([nodes[[0, 2]], np.zeros(2)]), name="bogie",
        model=Model(
            mesh=nodes, free_dofs=np.arange(6), prescribed=np.zeros(6), load_row=load_row,
            load_offset=k_v * float(lowering),
            params={"half_length": ell, "bending_stiffness": float(bending_stiffness),
                    "mount_stiffness": k_v, "tilt_stiffness": k_t, "lowering": float(lowering),
                    "gaps": (float(gap[0]), float(gap[1]))}))


def bogie_compliance(problem: ContactProblem) -> np.ndarray:
    """The closed-form ``W`` of :func:`bogie` from its parameters (see its docstring)."""
    p = problem.model.params
    ell, EI = p["half_length"], p["bending_stiffness"]
    own = ell ** 3 / (3 * EI) + 1 / p["mount_stiffness"] + ell ** 2 / p["tilt_stiffness"]
    other = 1 / p["mount_stiffness"] - ell ** 2 / p["tilt_stiffness"]
    return np.array([[own, other], [other, own]])


def bogie_deflection(problem: ContactProblem, u: np.ndarray,
                     samples: int = 101) -> tuple[np.ndarray, np.ndarray]:
    """The frame's deflection ``w(x)`` on ``[−ℓ, ℓ]`` by cubic Hermite interpolation of ``u``.

    On an element ``[x_a, x_b]`` of length ``h``, with ``s = (x − x_a)/h``:
    ``w = H₁ w_a + h H₂ θ_a + H₃ w_b + h H₄ θ_b`` with ``H₁ = 1 − 3s² + 2s³``,
    ``H₂ = s − 2s² + s³``, ``H₃ = 3s² − 2s³``, ``H₄ = −s² + s³``.
    """
    nodes = np.asarray(problem.model.mesh, dtype=float)
    full = problem.model.expand(np.asarray(u, dtype=float))
    x = np.linspace(nodes[0], nodes[-1], samples)
    element = np.clip(np.searchsorted(nodes, x, side="right") - 1, 0, nodes.size - 2)
    h = nodes[element + 1] - nodes[element]
    s = (x - nodes[element]) / h
    w_a, t_a = full[2 * element], full[2 * element + 1]
    w_b, t_b = full[2 * element + 2], full[2 * element + 3]
    w = ((1 - 3 * s ** 2 + 2 * s ** 3) * w_a + h * (s - 2 * s ** 2 + s ** 3) * t_a
         + (3 * s ** 2 - 2 * s ** 3) * w_b + h * (-s ** 2 + s ** 3) * t_b)
    return x, w
