"""Arrays a user hands in, converted or refused with the argument's name (never a NumPy traceback)."""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from signorini.errors import InputError


def sparse_argument(value: Any, name: str) -> sp.csr_matrix:
    """``value`` (a SciPy sparse matrix or a 2D array of numbers) as CSR floats, or InputError."""
    try:
        matrix = sp.csr_matrix(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be a sparse matrix or a 2D array of numbers, got "
                         f"{type(value).__name__} ({exc})") from None
    if matrix.ndim != 2:
        raise InputError(f"{name} must be two-dimensional, got shape {matrix.shape}")
    return matrix


def vector_argument(value: Any, name: str) -> np.ndarray:
    """``value`` as a 1D float array, or InputError naming ``name``."""
    try:
        vector = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a 1D array of numbers, got {type(value).__name__}") from None
    if vector.ndim != 1:
        raise InputError(f"{name} must be a 1D array of numbers, got shape {vector.shape}")
    return vector
