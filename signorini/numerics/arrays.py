"""Arrays a user hands in, converted or refused with the argument's name (never a NumPy traceback).

Complex values are refused rather than cast (the cast drops the imaginary
part with only a warning), and so are ``None`` entries (NumPy would turn them
into NaN, or a sparse matrix into zeros).
"""

from __future__ import annotations

import math
import warnings
from numbers import Real
from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import lobpcg

from signorini.errors import InputError


def _refuse_complex_or_none(value: Any, name: str) -> None:
    """InputError when ``value`` holds complex numbers or ``None`` entries."""
    if sp.issparse(value):
        raw = value.data
    else:
        try:
            raw = np.asarray(value)
        except (TypeError, ValueError):  # ragged or odd: the conversion says what it is
            return
    if np.iscomplexobj(raw):
        raise InputError(f"{name} must be real, got complex values: pass its real part "
                         f"(np.real({name})) if the imaginary part is zero")
    if raw.dtype == object:
        flat = raw.ravel()
        if any(v is None for v in flat):
            where = next(i for i, v in enumerate(flat) if v is None)
            at = tuple(int(i) for i in np.unravel_index(where, raw.shape))
            raise InputError(f"{name} has None at entry {at if len(at) > 1 else at[0]}: "
                             "give a number for every entry (0 where there is none)")
        if any(isinstance(v, complex) for v in flat):
            raise InputError(f"{name} must be real, got complex values: pass its real part")


def _compressed_fault(value: Any) -> str | None:
    """What is wrong with the index arrays of a CSR or CSC matrix (None when they are sound):
    SciPy builds one without looking at them, and its C code then reads out of bounds."""
    major, minor = value.shape if value.format == "csr" else value.shape[::-1]
    indptr, indices = np.asarray(value.indptr), np.asarray(value.indices)
    if indptr.ndim != 1 or indices.ndim != 1 or indptr.dtype.kind not in "iu" \
            or indices.dtype.kind not in "iu":
        return "indptr and indices must be 1-D arrays of integers"
    if indptr.size != major + 1 or indptr[0] != 0:
        return f"indptr must have {major + 1} entries starting at 0"
    if np.any(np.diff(indptr) < 0):
        return "indptr must not decrease"
    if indptr[-1] > min(indices.size, np.size(value.data)):
        return f"indptr ends at {int(indptr[-1])}, beyond the {indices.size} stored entries"
    used = indices[:indptr[-1]]
    if used.size and (used.min() < 0 or used.max() >= minor):
        return f"an index lies outside 0..{minor - 1}"
    return None


def sparse_argument(value: Any, name: str) -> sp.csr_matrix:
    """``value`` (a SciPy sparse matrix or a 2D array of numbers) as CSR floats, or InputError."""
    if value is None:
        raise InputError(f"{name} is None: give a sparse matrix or a 2D array of numbers")
    if sp.issparse(value) and value.format in ("csr", "csc"):
        fault = _compressed_fault(value)
        if fault is not None:
            raise InputError(f"{name} is not a valid {value.format.upper()} matrix ({fault}): "
                             f"build it from (data, (row, col)) with scipy.sparse.coo_matrix")
    _refuse_complex_or_none(value, name)
    try:
        matrix = sp.csr_matrix(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be a sparse matrix or a 2D array of numbers, got "
                         f"{type(value).__name__} ({exc})") from None
    if matrix.ndim != 2:
        raise InputError(f"{name} must be two-dimensional, got shape {matrix.shape}")
    return matrix


#: K is symmetric when ``|K − Kᵀ|`` is at most this fraction of its largest entry
SYMMETRY_RTOL = 1e-10


def symmetric_argument(K: sp.csr_matrix, name: str = "K") -> sp.csr_matrix:
    """``K`` when it is square and symmetric (to :data:`SYMMETRY_RTOL`), or InputError naming it."""
    if K.shape[0] != K.shape[1]:
        raise InputError(f"{name} must be square, got shape {K.shape}")
    if K.shape[0] and abs(K - K.T).max() > SYMMETRY_RTOL * abs(K).max():
        raise InputError(f"{name} must be symmetric: pass the stiffness matrix itself, or "
                         f"½({name} + {name}ᵀ)")
    return K


def _floats(value: Any, name: str, what: str) -> np.ndarray:
    """``value`` as an array of floats, or InputError saying that ``name`` must be ``what``."""
    _refuse_complex_or_none(value, name)
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be {what}, got {type(value).__name__}") from None


def vector_argument(value: Any, name: str) -> np.ndarray:
    """``value`` as a 1D float array, or InputError naming ``name``."""
    vector = _floats(value, name, "a 1D array of numbers")
    if vector.ndim != 1:
        raise InputError(f"{name} must be a 1D array of numbers, got shape {vector.shape}")
    return vector


def flag_argument(value: Any, name: str) -> bool:
    """A yes-or-no argument: a bool (or NumPy's), never a string or a number taken as true."""
    if not isinstance(value, (bool, np.bool_)):
        raise InputError(f"{name}={value!r} must be True or False")
    return bool(value)


def finite_real(value: Any) -> bool:
    """``value`` is a finite real number (a bool is not one)."""
    return not isinstance(value, bool) and isinstance(value, Real) and math.isfinite(value)


def multiplicity_argument(value: Any) -> float:
    """A model's ``force_multiplicity`` (copies of it in the whole body): a finite number > 0."""
    if not (finite_real(value) and value > 0):
        raise InputError(f"force_multiplicity={value!r} must be a finite number > 0: how many "
                         "copies of the model make the whole body (1 for the whole body, 2 for a "
                         "half model)")
    return float(value)


def dimension_of(N: sp.csr_matrix) -> int | None:
    """The dimension (2 or 3) N's rows show, or None when they show neither or both.

    A candidate's row holds its normal on the dofs of one node, numbered in
    blocks of ``dim`` consecutive dofs, so its nonzeros lie in one block.
    """
    rows, cols = N.nonzero()
    fits = [dim for dim in (2, 3) if N.shape[1] % dim == 0 and
            np.all(np.diff(cols // dim)[np.diff(rows) == 0] == 0)]
    return fits[0] if len(fits) == 1 else None


def points_argument(value: Any, N: sp.csr_matrix) -> np.ndarray:
    """Contact points (m, dim) for the rows of ``N`` (NaN when ``value`` is None), or InputError."""
    m = N.shape[0]
    if value is None:
        return np.full((m, dimension_of(N) or 2), np.nan)
    points = _floats(value, "contact_points", "an (m, 2) or (m, 3) array of numbers")
    if points.ndim != 2 or points.shape[0] != m or points.shape[1] not in (2, 3):
        raise InputError(f"contact_points must have shape ({m}, 2) or ({m}, 3), one row per "
                         f"candidate, got {points.shape}")
    if not np.all(np.isfinite(points)):
        row = int(np.flatnonzero(~np.all(np.isfinite(points), axis=1))[0])
        raise InputError(f"contact_points row {row} is {points[row].tolist()}: give finite "
                         "coordinates for every candidate, or leave contact_points out")
    dim = dimension_of(N)
    if dim is not None and points.shape[1] != dim:
        raise InputError(f"contact_points have {points.shape[1]} columns but N's rows are those of a "
                         f"{dim}D problem (each on {dim} consecutive dofs of one node): give ({m}, {dim})")
    return points


#: K is indefinite when an eigenvalue lies below this fraction of its largest diagonal entry
NEGATIVE_CURVATURE = 1e-10
#: up to this many dofs the lowest eigenvalue of K is found densely, beyond it is bounded above
#: by LOBPCG's Rayleigh quotient after at most :data:`CURVATURE_STEPS` iterations
DENSE_EIGEN_DOFS = 500
CURVATURE_STEPS = 50


def indefinite(K) -> bool:
    """Whether ``K`` has a negative eigenvalue (below ``−NEGATIVE_CURVATURE · max|Kᵢᵢ|``): then
    ``½uᵀKu − fᵀu`` has no minimum and a KKT point is no answer. Exact up to
    :data:`DENSE_EIGEN_DOFS` dofs; beyond, a Rayleigh quotient below the bound proves it (one
    above says nothing: False)."""
    scale = float(np.max(np.abs(K.diagonal()), initial=0.0)) or 1.0
    if K.shape[0] <= DENSE_EIGEN_DOFS:
        lowest = np.linalg.eigvalsh(K.toarray())[0]
    else:
        start = np.random.default_rng(0).standard_normal((K.shape[0], 1))
        with warnings.catch_warnings():  # an unconverged quotient still bounds the lowest above
            warnings.simplefilter("ignore")
            lowest = lobpcg(K, start, largest=False, maxiter=CURVATURE_STEPS, tol=1e-8)[0][0]
    return bool(lowest < -NEGATIVE_CURVATURE * scale)


__all__ = ["sparse_argument", "symmetric_argument", "vector_argument", "flag_argument",
           "finite_real", "multiplicity_argument", "dimension_of", "points_argument",
           "CURVATURE_STEPS", "DENSE_EIGEN_DOFS", "NEGATIVE_CURVATURE", "indefinite"]
