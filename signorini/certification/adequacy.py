"""Is the model adequate for the answer? The boundary beyond the contact candidates, watched.

The QP only knows the candidates a scene chose before the solve (for Hertz's
cylinder, the arc up to ``candidates · a``). An answer can be exact for that
QP and still wrong for the body: push harder and boundary nodes beyond the
candidates go through the obstacle, unseen. After every solve the package
therefore checks the whole boundary (:class:`signorini.problem.contact.Watch`, built
at assembly):

- a boundary node that is not a candidate lies on the wrong side of the
  obstacle (by more than the accepted primal residual), or
- an *edge candidate* — one that shares a boundary facet facing the obstacle
  with a node that is not a candidate — is in contact, so the contact zone
  may go on beyond the candidates.

Either makes the result ``model_inadequate`` with a message naming what to
change. Warnings that keep the status: ν > 0.45 with plain P1 triangles (volumetric
locking: docs/accuracy.md and the atlas's ν axis; not with volumetric=nodal) and an obstacle that starts
inside the body by more than the push.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from signorini.errors import docs_page
from signorini.certification.kkt import ACTIVE, classify, gap_scale
from signorini.problem.contact import ContactProblem, ContactSolution

#: above this Poisson's ratio P1 triangles lock measurably (docs/accuracy.md: 3–5 × the error)
LOCKING_NU = 0.45


@dataclass(frozen=True)
class Adequacy:
    """What the watch found: the deepest penetration beyond the candidates, active edge candidates."""

    penetration: float          # physical length (0 when nothing beyond the candidates penetrates)
    relative_penetration: float  # over the gap scale of the certificate
    penetrating_nodes: int
    edge_active: int
    remedy: str

    def inadequate(self, accept: float) -> bool:
        return self.relative_penetration > accept or self.edge_active > 0

    def message(self) -> str:
        said = []
        if self.penetrating_nodes:
            said.append(f"{self.penetrating_nodes} boundary node(s) beyond the contact candidates "
                        f"went through the obstacle (by up to {self.penetration:.3g})")
        if self.edge_active:
            said.append("the outermost contact candidate is in contact, so the zone may go on "
                        "beyond the candidates")
        return "; ".join(said) + f": the model is not adequate for this load: {self.remedy}"

    def as_dict(self) -> dict[str, float | int]:
        return {"penetration": self.penetration, "relative_penetration": self.relative_penetration,
                "penetrating_nodes": self.penetrating_nodes, "edge_active": self.edge_active}


def adequacy(problem: ContactProblem, solution: ContactSolution, accept: float) -> Adequacy | None:
    """Check the boundary beyond the candidates (None when the problem has no watch or no answer)."""
    watch = problem.model.watch
    if watch is None or not np.all(np.isfinite(solution.u)):
        return None
    gaps = watch.gap(problem, solution.u)
    scale = gap_scale(problem, solution.u)
    deepest = float(max(-gaps.min(), 0.0)) if gaps.size else 0.0
    penetrating = int(np.sum(-gaps > accept * scale))
    labels = classify(problem, solution)
    edge_active = int(np.sum(labels[watch.edge] == ACTIVE)) if watch.edge.size else 0
    return Adequacy(penetration=deepest * problem.scales.displacement,
                    relative_penetration=deepest / scale, penetrating_nodes=penetrating,
                    edge_active=edge_active, remedy=watch.remedy)


#: a contact on fewer candidates than this resolves no pressure profile
FEWEST_IN_CONTACT = 3


def warnings(problem: ContactProblem, solution: ContactSolution | None = None) -> list[str]:
    """What may make an exact answer a poor model (the status stays)."""
    said = []
    touching = None if solution is None else int(np.sum(solution.lam > 0))
    if problem.model.reference_name and touching is not None and 0 < touching < FEWEST_IN_CONTACT:
        said.append(f"the contact covers {touching} candidate(s), too few to resolve it (its "
                    "width and peak pressure cannot be fitted): refine the mesh at the contact "
                    "or raise the load")
    model = problem.model
    bodies = [(nu, volumetric) for _, _, nu, volumetric in model.materials] or \
        [(model.nu, model.volumetric)]  # each body of a pair its own
    locking = max((nu for nu, volumetric in bodies if volumetric == "element"), default=0.0)
    if locking > LOCKING_NU:
        said.append(f"ν = {locking:g} > {LOCKING_NU:g}: P1 triangles lock, the pressure can be several "
                    f"percent off ({docs_page('accuracy')}); set the scene parameter volumetric=nodal "
                    "(the volumetric strain averaged at the nodes: no locking)")
    watch = model.watch
    if watch is not None and watch.candidate_gaps.size:
        push = float(np.max(np.abs(model.prescribed), initial=0.0))
        inside = float(-watch.candidate_gaps.min())
        if inside > 0 and inside > push:
            said.append(f"the obstacle starts {inside * problem.scales.displacement:.3g} inside the "
                        f"body, more than the push ({push * problem.scales.displacement:.3g}): check "
                        "its position")
    return said


__all__ = ["Adequacy", "adequacy", "warnings"]
