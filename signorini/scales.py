"""The units that make a contact problem dimensionless (:class:`Scales`), and how they are chosen
for a QP given as arrays (:func:`qp_scales`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

__all__ = ["Scales", "qp_scales"]


@dataclass(frozen=True)
class Scales:
    """Units that make the problem dimensionless.

    A physical quantity is its dimensionless value times its scale:
    coordinates ``x = length · x̂``, displacements and gaps
    ``u = displacement · û``, contact forces ``λ = force · λ̂``, weights
    ``w = weight · ŵ`` and pressures ``p = λ / w = pressure · p̂`` with
    ``pressure = force / weight``. In 2D (per unit thickness)
    ``force = E · displacement`` and ``weight = length``; in 3D and in
    axisymmetric models ``force = E · displacement · length`` and
    ``weight = length²``. Axisymmetric forces and weights (``∫ φᵢ r ds``) are
    **per radian**; ``force_multiplicity`` (2π times any other copies) turns
    ``Σλ`` into the force on the whole body. Scaling the
    displacement apart from the geometry matters: a Hertz contact at
    a/R = 0.05 moves by about 1e-3 R, and a solver's absolute tolerances
    only mean something when the unknowns are of order one.
    """

    length: float = 1.0
    displacement: float = 1.0
    force: float = 1.0
    weight: float = 1.0

    @property
    def pressure(self) -> float:
        return self.force / self.weight


def qp_scales(K: sp.spmatrix, f: np.ndarray, d: np.ndarray,
              weights: np.ndarray | None = None) -> Scales:
    """The units that make a QP given as arrays dimensionless, by a scene's rule.

    A scene divides K by its stiffness ``E·L^k`` and displacements by its
    largest prescribed displacement, else its largest gap. A QP given as arrays
    has its prescribed displacements lifted into f and d, so: the stiffness
    ``k`` is the mean of K's diagonal, the displacement ``U`` the larger of
    ``‖d‖∞`` and ``‖f‖∞ / k`` (the gaps, and how far the load moves one dof),
    the force ``k·U`` (so that ``K̂ = K/k``, ``f̂ = f/(k·U)``, ``d̂ = d/U`` and
    ``λ̂ = λ/(k·U)``) and the weight the mean weight. A scale that comes out
    zero is 1; lengths keep the user's unit.
    """
    diagonal = np.abs(K.diagonal())
    stiffness = float(np.mean(diagonal)) if diagonal.size else 0.0
    stiffness = stiffness if np.isfinite(stiffness) and stiffness > 0 else 1.0
    largest = max(float(np.max(np.abs(d), initial=0.0)),
                  float(np.max(np.abs(f), initial=0.0)) / stiffness)
    displacement = largest if np.isfinite(largest) and largest > 0 else 1.0
    weight = float(np.mean(weights)) if weights is not None and weights.size else 1.0
    return Scales(length=1.0, displacement=displacement, force=stiffness * displacement,
                  weight=weight)
