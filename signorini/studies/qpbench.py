"""Contact QPs as a qpbenchmark test set, each with its certified answer.

Each problem is one scene's QP ``min ½uᵀKu − fᵀu  s.t.  Nu ≤ d`` in qpsolvers' form
``min ½xᵀPx + qᵀx  s.t.  Gx ≤ h`` with ``P = K``, ``q = −f``, ``G = N``, ``h = d``, in the
scene's own units (not rescaled: the conditioning its user's QP has). The reference answer
``(x*, z*)`` is pdas's on exactly the stored arrays, judged by the KKT certificate
(:func:`signorini.certificate`, forward error included) on those same arrays.

The families (:data:`FAMILIES`) and what each one tests:

- ``HERTZCYL*``, ``HERTZSPH*``: the Hertz cylinder and sphere at three mesh sizes;
- ``NU*``: a nearly incompressible body (ν = 0.45, 0.499, 0.4999): K's conditioning grows as
  1/(1 − 2ν);
- ``UNITS*``: the same cylinder in SI (Pa, m) and in mm–MPa: the unscaled magnitudes a user's
  QP has (entries of K near 10¹¹ in SI);
- ``EDGE*``: weakly active constraints (gap 0 and force 0): a wide contact zone (large a/R),
  the flat punch's corner and a block whose outer bottom touches with no force;
- ``SPH3D``: the 3D sphere (a quarter model), with ``three_d=True``;
- ``TWOBODY*``: two elastic bodies, from the scenes ``hertz-two-cylinders`` and
  ``two-block-patch`` once they are registered (left out while they are not).

The layout written (:func:`export`) follows qpbenchmark's test sets: ``signorini_contact.py``
(the :class:`qpbenchmark.TestSet`), ``signorini_contact_dense.py`` (the dense subset),
``data/NAME.npz`` (one problem and its reference answer), ``results/`` and ``README.md``.
Every file is a function of the problem data alone: exporting twice gives the same bytes.
"""

from __future__ import annotations

import json
import logging
import os
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp

from signorini.api import certificate, scene_families, solve
from signorini.errors import InputError
from signorini.problem.contact import ContactProblem
from signorini.studies import qpbench_files

__all__ = ["CERTIFIED_TOL", "DENSE_MAX_DOFS", "FAMILIES", "Entry", "Reference", "entries", "export", "reference"]

log = logging.getLogger(__name__)

#: problems with at most this many unknowns form the dense subset (a dense P of 2000² doubles
#: is 32 MB)
DENSE_MAX_DOFS = 2000
#: the tolerance pdas is asked for; the stored answer is certified at what it reached
REFERENCE_TOL = 1e-12
#: what every stored answer must pass (relative, every residual and the forward error)
CERTIFIED_TOL = 1e-10


@dataclass(frozen=True)
class Entry:
    """One problem of the test set: its name, family, scene and the scene's parameters."""

    name: str
    family: str
    scene: str
    params: dict[str, Any] = field(default_factory=dict)
    what: str = ""


def _hertz(refine: int) -> list[Entry]:
    out = []
    for size, (n_cyl, n_sph) in enumerate(((10, 15), (20, 30), (40, 60))):
        out.append(Entry(f"HERTZCYL{size}", "hertz", "hertz-cylinder",
                         {"n_contact": n_cyl, "refine": refine},
                         f"Hertz cylinder, plane strain, {n_cyl} elements across the half-width"))
        out.append(Entry(f"HERTZSPH{size}", "hertz", "hertz-sphere",
                         {"n_contact": n_sph, "refine": refine},
                         f"Hertz sphere, axisymmetric, {n_sph} elements across the radius"))
    return out


def _nearly_incompressible(refine: int) -> list[Entry]:
    return [Entry(f"NU{str(nu).replace('.', '')}", "nu", "hertz-cylinder",
                  {"nu": nu, "n_contact": 20, "refine": refine},
                  f"Hertz cylinder at ν = {nu}") for nu in (0.45, 0.499, 0.4999)]


def _units(refine: int) -> list[Entry]:
    return [Entry("UNITSSI", "units", "hertz-cylinder",
                  {"E": 2.1e11, "R": 0.01, "n_contact": 20, "refine": refine},
                  "steel cylinder in SI: E = 2.1e11 Pa, R = 0.01 m"),
            Entry("UNITSMM", "units", "hertz-cylinder",
                  {"E": 2.1e5, "R": 10.0, "n_contact": 20, "refine": refine},
                  "the same cylinder in mm and MPa: E = 2.1e5 MPa, R = 10 mm")]


def _edges(refine: int) -> list[Entry]:
    return [Entry("EDGEWIDE", "edge", "hertz-cylinder",
                  {"a_over_R": 0.3, "n_contact": 20, "refine": refine},
                  "a wide contact zone (a/R = 0.3): the zone's edge between nodes"),
            Entry("EDGEPUNCH", "edge", "punch", {"n_contact": 16, "size": 10.0, "refine": refine},
                  "flat punch with sharp corners: a singular pressure at the corner"),
            Entry("EDGEBLOCK", "edge", "block",
                  {"touching": 0.5, "nx": 16 * 2 ** refine, "ny": 16 * 2 ** refine},
                  "block whose outer bottom half touches with zero force (weakly active)")]


def _three_d(refine: int) -> list[Entry]:
    return [Entry("SPH3D", "3d", "hertz-sphere-3d", {"n_contact": 10, "refine": refine},
                  "Hertz sphere, 3D quarter model")]


def _two_bodies(refine: int) -> list[Entry]:
    """Two elastic bodies: included when the scenes are registered."""
    return [Entry("TWOBODYCYL", "two-bodies", "hertz-two-cylinders", {},
                  "two elastic cylinders (two bodies, one contact pair)"),
            Entry("TWOBODYPATCH", "two-bodies", "two-block-patch", {},
                  "two blocks on non-matching meshes: the contact patch test")]


#: the families by name: each a function of the number of uniform refinements
FAMILIES: dict[str, Callable[[int], list[Entry]]] = {
    "hertz": _hertz, "nu": _nearly_incompressible, "units": _units, "edge": _edges,
    "3d": _three_d, "two-bodies": _two_bodies}


def entries(refine: int = 0, three_d: bool = False) -> list[Entry]:
    """The test set's problems, in a fixed order.

    ``refine`` uniform refinements apply to every 2D and axisymmetric scene (each about 4× the
    unknowns); the 3D family comes with ``three_d`` (its refinements 8× each). Families whose
    scene is not registered are left out.
    """
    if isinstance(refine, bool) or not isinstance(refine, int) or refine < 0:
        raise InputError(f"refine must be a whole number ≥ 0, got {refine!r}")
    known = scene_families()
    chosen = [e for name, family in FAMILIES.items() if name != "3d" or three_d
              for e in family(refine)]
    missing = sorted({e.scene for e in chosen if e.scene not in known})
    if missing:
        log.info("left out (scene not registered): %s", ", ".join(missing))
    return [e for e in chosen if e.scene in known]


@dataclass
class Reference:
    """One exported problem: its QP in qpsolvers' form and its certified answer."""

    entry: Entry
    P: sp.csc_matrix
    q: np.ndarray
    G: sp.csc_matrix
    h: np.ndarray
    x: np.ndarray
    z: np.ndarray
    certificate: dict[str, float]

    def worst(self) -> tuple[str, float]:
        """The certificate's largest residual (NaN entries, not estimated, left out)."""
        known = {k: v for k, v in self.certificate.items() if not np.isnan(v)}
        name = max(known, key=lambda k: known[k])
        return name, known[name]

    @property
    def certified(self) -> bool:
        """Whether every residual and the forward error are at most :data:`CERTIFIED_TOL`."""
        return self.worst()[1] <= CERTIFIED_TOL

    def arrays(self) -> dict[str, np.ndarray]:
        """What the problem's .npz holds, in a fixed order."""
        out: dict[str, np.ndarray] = {}
        for key, matrix in (("P", self.P), ("G", self.G)):
            out.update({f"{key}_data": matrix.data, f"{key}_indices": matrix.indices.astype(np.int64),
                        f"{key}_indptr": matrix.indptr.astype(np.int64),
                        f"{key}_shape": np.array(matrix.shape, dtype=np.int64)})
        names = list(self.certificate)
        out.update({"q": self.q, "h": self.h, "x_ref": self.x, "z_ref": self.z,
                    "certificate_names": np.array(names),
                    "certificate_values": np.array([self.certificate[k] for k in names]),
                    "scene": np.array(self.entry.scene),
                    "params": np.array(json.dumps(self.entry.params, sort_keys=True))})
        return out


def _csc(matrix) -> sp.csc_matrix:
    out = sp.csc_matrix(matrix, dtype=np.float64)
    out.sum_duplicates()
    out.sort_indices()
    return out


def reference(entry: Entry) -> Reference:
    """Build the entry's scene at its load, export its QP and certify pdas's answer on it.

    The scene is solved once to meet its load (load control); pdas then solves the QP made
    from the exported arrays alone (:meth:`ContactProblem.from_qp`), so that the stored answer
    and its certificate are those of exactly the stored problem.
    """
    loaded = solve(entry.scene, "pdas", tol=REFERENCE_TOL, params=entry.params)
    K, f, N, d = loaded.problem.qp()
    P, G = _csc(0.5 * (K + K.T)), _csc(N)
    q, h = -np.asarray(f, dtype=np.float64), np.asarray(d, dtype=np.float64)
    qp = ContactProblem.from_qp(P, -q, G, h, name=entry.name)
    answer = solve(qp, "pdas", tol=REFERENCE_TOL)
    x = np.asarray(answer.u, dtype=np.float64)
    # a weakly active candidate's force may end a round-off below zero (pdas accepts it within
    # tol); the stored z is a dual point of qpsolvers' form, z ≥ 0, and is certified as stored
    z = np.maximum(np.asarray(answer.force, dtype=np.float64), 0.0)
    cert = certificate(qp, u=x, force=z)
    if not cert.passed(CERTIFIED_TOL):
        log.warning("%s: pdas's answer is certified only at %.1e (%s), above %g",
                    entry.name, cert.worst()[1], cert.worst()[0], CERTIFIED_TOL)
    log.info("%s: n = %d, m = %d, certified at %.1e", entry.name, P.shape[0], G.shape[0],
             cert.worst()[1])
    return Reference(entry, P, q, G, h, x, z, {k: float(v) for k, v in cert.residuals().items()})


def export(directory: str, *, refine: int = 0, three_d: bool = False,
           only: list[str] | None = None) -> list[Reference]:
    """Write the test set into ``directory`` (created; its files replaced, and problems a
    previous export left in ``data/`` removed: the folder holds this command's set alone).

    ``only`` keeps the named problems (InputError for a name not in the set). Returns what
    was written, in the test set's order.
    """
    chosen = entries(refine, three_d)
    if only:
        unknown = sorted(set(only) - {e.name for e in chosen})
        if unknown:
            raise InputError(f"--only {', '.join(unknown)}: not in the test set; the names are "
                             + ", ".join(e.name for e in chosen))
        chosen = [e for e in chosen if e.name in set(only)]
    refs = [reference(e) for e in chosen]
    data = os.path.join(directory, "data")
    os.makedirs(data, exist_ok=True)
    os.makedirs(os.path.join(directory, "results"), exist_ok=True)
    written = {f"{ref.entry.name}.npz" for ref in refs}
    for stale in sorted(set(os.listdir(data)) - written):
        if stale.endswith(".npz"):
            log.info("removing %s: not in this export", stale)
            os.remove(os.path.join(data, stale))
    for ref in refs:
        qpbench_files.write_npz(os.path.join(data, f"{ref.entry.name}.npz"), ref.arrays())
    qpbench_files.write_test_set(directory, refs, DENSE_MAX_DOFS)
    return refs
