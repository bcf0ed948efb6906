"""Whether a QP has a minimum at all: ``½uᵀKu − fᵀu`` has none when K has a negative eigenvalue,
and a point meeting the KKT conditions is then no answer (the certificate's duality gap is inf).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from signorini.numerics.arrays import DENSE_EIGEN_DOFS, NEGATIVE_CURVATURE
from signorini.numerics.arrays import indefinite as negative_quotient
from signorini.numerics.factor import available_backends, factorize

__all__ = ["NoMinimum", "indefinite"]


class NoMinimum(np.linalg.LinAlgError):
    """K has a negative eigenvalue (:func:`indefinite` said so): the QP has no minimum."""


def indefinite(K) -> bool:
    """K has an eigenvalue below ``−NEGATIVE_CURVATURE · max|Kᵢᵢ|``: dense eigenvalues or a
    Rayleigh quotient say so (:func:`signorini.numerics.arrays.indefinite`), else, beyond the
    dense size, where the quotient may not reach the eigenvalue in its few steps, K shifted up by
    that much still fails CHOLMOD's factorisation (its pivots judged as for K itself)."""
    if negative_quotient(K):
        return True
    if K.shape[0] <= DENSE_EIGEN_DOFS or "cholmod" not in available_backends():
        return False  # dense eigenvalues are exact; without CHOLMOD the quotient is all there is
    shift = NEGATIVE_CURVATURE * (float(np.max(np.abs(K.diagonal()))) or 1.0)
    try:
        factorize(sp.csr_matrix(K + shift * sp.eye(K.shape[0])), backend="cholmod")
    except np.linalg.LinAlgError:
        return True
    return False
