"""The units that make a contact problem dimensionless (:class:`Scales`), and the units of a
solve record (:func:`record_units`).

A problem holds its QP in the units it was given (:meth:`ContactProblem.from_qp`
keeps the user's arrays); a scene's model makes its QP dimensionless and says how to go back
in its ``scales``. A method that needs numbers of order one is handed a private view of a
problem in such units when it runs (:func:`signorini.solvers.registry.scaled_view`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = ["Scales", "record_units"]


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


def record_units(problem: Any) -> dict[str, str]:
    """The unit of each physical quantity of the solve record, in the problem's input units.

    A scene's units are those of its parameters: ``length`` the unit its lengths are given in
    (R, W, H, mesh coordinates), ``stress`` the unit of E; so a scene given in SI has lengths
    in m and pressures in Pa. A problem from its QP data (:meth:`ContactProblem.from_qp`) is in
    the units of d (lengths) and of f (forces).
    """
    if problem.model.mesh is None:
        return {"system": "the QP's own", "length": "the unit of d", "force": "the unit of f",
                "total_force": "the unit of f", "pressure": "the unit of f per unit of the weights",
                "time": "s"}
    if problem.model.mesh.p.shape[0] == 2 and not problem.model.axisymmetric:
        force = total = "stress·length (per unit thickness, plane strain)"
    else:
        total = "stress·length²"
        force = total + (" (per radian: axisymmetric)" if problem.model.axisymmetric else "")
    return {"system": "the scene's own (length: its lengths' unit, stress: E's unit)",
            "length": "length", "force": force, "total_force": total, "pressure": "stress",
            "time": "s"}
