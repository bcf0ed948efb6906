"""The package's own problem file, which :meth:`ContactProblem.save` writes and ``load`` reads.

One ``.npz`` holding K and N by their CSR parts, f, d, weights, contact points, the mesh and
what the scene's model says (a ``meta`` JSON object). A QP of your own is stored in its own
units (identity scales); a scene's problem in its dimensionless units with its scales.
"""

from __future__ import annotations

import dataclasses
import io
import json
import logging
import os
import zipfile
from typing import Any

import numpy as np
import scipy.sparse as sp

from signorini.problem.model import Model, Push, ReferenceData, Watch
from signorini.errors import InputError
from signorini.files import atomic_write_bytes
from signorini.numerics.arrays import sparse_argument, symmetric_argument
from signorini.paths import check_input_file
from signorini.problem.scales import Scales

log = logging.getLogger(__name__)

__all__ = ["in_given_units", "load", "save"]


def save(problem: Any, path: str | os.PathLike) -> None:
    """Store ``problem`` (arrays, mesh, the model's record) in ``path``, atomically."""
    K, N = problem.K.tocsr(), problem.N.tocsr()
    arrays = dict(
        K_data=K.data, K_indices=K.indices, K_indptr=K.indptr, N_data=N.data,
        N_indices=N.indices, N_indptr=N.indptr, shape=np.array([problem.n, problem.m]), f=problem.f,
        d=problem.d, weights=problem.weights if problem.weights is not None else np.zeros(0),
        contact_points=problem.contact_points)
    meta: dict[str, Any] = {"scene": problem.name, "force_multiplicity": problem.force_multiplicity,
                            "scales": vars(problem.scales), "discretisation": None}
    disc = problem.model
    if not disc.empty:
        arrays.update(free_dofs=disc.free_dofs, prescribed=disc.prescribed,
                      load_row=disc.load_row if disc.load_row is not None else np.zeros(0))
        if disc.mesh is not None:  # node blocks and rigid modes for the petsc methods
            arrays.update(mesh_p=disc.mesh.p, mesh_t=disc.mesh.t)
        pu = disc.push
        if pu is not None:
            arrays.update(push_f1=pu.f1, push_d0=pu.d0, push_d1=pu.d1)
            optional = {"push_f_load": pu.f_load, "push_resultant": pu.resultant}
            arrays.update({name: value for name, value in optional.items() if value is not None})
        if disc.predicted_contact is not None:  # where load control starts
            arrays.update(predicted_contact=disc.predicted_contact)
        watch = disc.watch
        if watch is not None:  # the boundary beyond the candidates: the model's adequacy is judged
            rows = sp.csr_matrix(watch.rows)
            arrays.update(watch_data=rows.data, watch_indices=rows.indices, watch_indptr=rows.indptr,
                          watch_gaps=watch.gaps, watch_edge=watch.edge,
                          watch_candidate_gaps=watch.candidate_gaps)
            if watch.nodes is not None:
                arrays.update(watch_nodes=watch.nodes)
        meta["discretisation"] = {
            "load_offset": disc.load_offset, "E": disc.E, "nu": disc.nu,
            "volumetric": disc.volumetric, "axisymmetric": disc.axisymmetric,
            "reference": None if disc.reference is None else dataclasses.asdict(disc.reference),
            "params": disc.params, "assemble_s": disc.assemble_s,
            "materials": [list(m) for m in disc.materials],
            "watch": None if disc.watch is None else {"remedy": disc.watch.remedy,
                                                      "columns": disc.watch.rows.shape[1]},
            "push": None if pu is None else {"offset1": pu.offset1, "scale": pu.scale,
                                             "offset_load": pu.offset_load, "load": pu.load,
                                             "target": pu.target, "pending": disc.pending,
                                             "delta": pu.delta, "P": pu.P}}
    arrays["meta"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    atomic_write_bytes(path, buffer.getvalue())


def load(path: str | os.PathLike, problem_type: type) -> Any:
    """The problem (a ``problem_type``, :class:`signorini.ContactProblem`) :func:`save` stored in
    ``path``; InputError when it is missing, not a regular file or not an archive, or when its
    meta or K is not what :func:`save` writes."""
    check_input_file(os.fspath(path), "problem file", "give the path ContactProblem.save wrote")
    if not zipfile.is_zipfile(path):  # np.load would try it as a pickle
        raise InputError(f"problem file {os.fspath(path)!r} is not an archive ContactProblem.save "
                         "wrote: give the path it wrote")
    z = np.load(path, allow_pickle=False)
    meta = json.loads(bytes(z["meta"]).decode())
    if not isinstance(meta, dict):
        raise InputError(f"problem file {os.fspath(path)!r}: its meta holds a JSON "
                         f"{type(meta).__name__}, not the object ContactProblem.save writes: "
                         "save the problem again")
    n, m = (int(v) for v in z["shape"])
    model = None
    about = meta.get("discretisation")
    if about is not None:
        push = None
        if about["push"] is not None:
            p = about["push"]
            push = Push(z["push_f1"], z["push_d0"], z["push_d1"], p["offset1"], p["scale"],
                        z["push_f_load"] if "push_f_load" in z else None, p["offset_load"],
                        p["load"], p["target"],
                        z["push_resultant"] if "push_resultant" in z else None,
                        p.get("delta"), p.get("P"))
        mesh = None
        if "mesh_p" in z:
            from skfem import MeshTet, MeshTri  # a saved mesh only (start-up)

            kind = MeshTri if z["mesh_t"].shape[0] == 3 else MeshTet
            mesh = kind(z["mesh_p"], z["mesh_t"])
        model = Model(
            mesh=mesh, free_dofs=z["free_dofs"], prescribed=z["prescribed"],
            load_row=z["load_row"] if z["load_row"].size else None,
            load_offset=about["load_offset"], E=about["E"], nu=about["nu"],
            volumetric=about["volumetric"], axisymmetric=about["axisymmetric"],
            reference=_reference_data(about["reference"]), params=about["params"], push=push,
            pending=about["push"] is not None and about["push"]["pending"],
            assemble_s=about["assemble_s"],
            materials=tuple(tuple(m) for m in about.get("materials", ())),
            predicted_contact=z["predicted_contact"] if "predicted_contact" in z else None,
            watch=_watch(z, about.get("watch"), z["prescribed"].size))
    K = symmetric_argument(sp.csr_matrix((z["K_data"], z["K_indices"], z["K_indptr"]),
                                         shape=(n, n)))
    problem = problem_type(
        K=K, f=z["f"], N=sp.csr_matrix((z["N_data"], z["N_indices"], z["N_indptr"]), shape=(m, n)),
        d=z["d"], weights=z["weights"] if z["weights"].size else None,
        contact_points=z["contact_points"], force_multiplicity=meta["force_multiplicity"],
        scales=Scales(**meta["scales"]), name=meta["scene"], model=model)
    return problem if model is not None else in_given_units(problem)


def in_given_units(problem: Any) -> Any:
    """A problem without a model in the units its arrays were given in (identity scales).

    A QP given as arrays was once stored scaled, with the scales that undo it; the same QP
    in its own units is ``K·force/displacement``, ``f·force``, ``d·displacement`` and
    ``weights·weight``.
    """
    s = problem.scales
    if s == Scales():
        return problem
    return dataclasses.replace(
        problem, K=problem.K * (s.force / s.displacement), f=problem.f * s.force,
        d=problem.d * s.displacement, scales=Scales(),
        weights=None if problem.weights is None else problem.weights * s.weight,
        contact_points=problem.contact_points * s.length)


def _watch(z: Any, stored: dict[str, Any] | None, dofs: int) -> Watch | None:
    """The boundary beyond the candidates :func:`save` stored (None when the model had none),
    its rows checked before SciPy's C code reads them; ValueError when they do not fit."""
    if stored is None:
        return None
    rows = sparse_argument(sp.csr_matrix((z["watch_data"], z["watch_indices"], z["watch_indptr"]),
                                         shape=(z["watch_gaps"].size, stored["columns"])), "watch")
    if rows.shape[1] != dofs:
        raise ValueError(f"its watch has {rows.shape[1]} columns and its model {dofs} dofs")
    return Watch(rows, z["watch_gaps"], z["watch_edge"], z["watch_candidate_gaps"],
                 stored["remedy"], z["watch_nodes"] if "watch_nodes" in z else None)


def _reference_data(stored: Any) -> ReferenceData | None:
    """The reference record :meth:`ContactProblem.save` stored; a file that stored the name
    alone (an older version) has no record to compare with: rebuild it from its scene."""
    if isinstance(stored, dict):
        return ReferenceData(**stored)
    if stored:
        log.warning("the stored problem names its reference %r without the record it reads: "
                    "rebuild the problem from its scene to compare with the reference", stored)
    return None
