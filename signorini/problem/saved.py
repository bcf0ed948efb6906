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
import math
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

__all__ = ["declared_sizes", "in_given_units", "load", "save"]


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
    try:
        with np.load(path, allow_pickle=False) as z:
            declared_sizes(os.fspath(path), z.zip)  # before an array of a declared size is made
            arrays = {name: z[name] for name in z}  # each read from the archive once
        return _read(arrays, problem_type)
    except InputError as exc:
        text = str(exc)
        if text.startswith("problem file"):
            raise
        raise InputError(f"problem file {os.fspath(path)!r}: {text}: save the problem again "
                         "with ContactProblem.save") from None
    except (KeyError, ValueError, TypeError, EOFError, OSError,
            zipfile.BadZipFile) as exc:
        raise InputError(f"problem file {os.fspath(path)!r} is not what ContactProblem.save "
                         f"writes ({type(exc).__name__}: {exc}): save the problem again") from None


def declared_sizes(path: str, archive: zipfile.ZipFile) -> dict[str, tuple[int, ...]]:
    """The shape each array's header declares, by name; InputError for an array whose header
    declares more bytes than its member of the archive holds (read before it is allocated)."""
    declared = {}
    for info in archive.infolist():
        with archive.open(info) as member:
            try:
                fmt = np.lib.format
                header = fmt.read_array_header_1_0 if fmt.read_magic(member) == (1, 0) else \
                    fmt.read_array_header_2_0
                shape, _, dtype = header(member)
            except ValueError:
                continue  # not an array: np.load says so
        if dtype.itemsize * math.prod(shape) > info.file_size:
            raise InputError(f"problem file {path!r}: {info.filename.removesuffix('.npy')!r} "
                             f"declares shape {shape} ({dtype}), more than the {info.file_size} "
                             "bytes stored: write it again with numpy.savez")
        declared[info.filename.removesuffix(".npy")] = shape
    return declared


def _read(z: dict[str, np.ndarray], problem_type: type) -> Any:
    """The problem in the arrays ``z`` read from the archive, its arrays and meta checked first
    (:func:`_fits`)."""
    if "meta" not in z:
        raise InputError("it holds no 'meta'")
    try:
        meta = json.loads(bytes(z["meta"]).decode())
    except (ValueError, RecursionError) as exc:  # not UTF-8, not JSON, nested past the stack
        raise InputError(f"its meta is not the JSON object ContactProblem.save writes "
                         f"({type(exc).__name__})") from None
    if not isinstance(meta, dict):
        raise InputError(f"its meta holds a JSON {type(meta).__name__}, not the object "
                         "ContactProblem.save writes")
    n, m = _fits(z, meta)
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
    K = symmetric_argument(sparse_argument(
        sp.csr_matrix((z["K_data"], z["K_indices"], z["K_indptr"]), shape=(n, n)),
        "K (K_data, K_indices, K_indptr)"))
    N = sparse_argument(sp.csr_matrix((z["N_data"], z["N_indices"], z["N_indptr"]), shape=(m, n)),
                        "N (N_data, N_indices, N_indptr)")
    problem = problem_type(
        K=K, f=z["f"], N=N,
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


#: the arrays :func:`save` writes, by name: their kind (NumPy's letters) and shape, in terms of
#: n unknowns, m candidates, D the model's dofs (``prescribed``), P mesh points; -1: any size
#: (every float array finite but the contact points, unknown (NaN) for a QP given as arrays)
_ARRAYS = {
    "shape": ("iu", (2,)), "K_data": ("f", (-1,)), "K_indices": ("iu", (-1,)),
    "K_indptr": ("iu", ("n+1",)), "N_data": ("f", (-1,)), "N_indices": ("iu", (-1,)),
    "N_indptr": ("iu", ("m+1",)), "f": ("f", ("n",)), "d": ("f", ("m",)),
    "weights": ("f", ("m|0",)), "contact_points": ("f", ("m", -1)), "free_dofs": ("iu", ("n",)),
    "prescribed": ("f", ("D",)), "load_row": ("f", ("n|0",)), "mesh_p": ("f", (-1, "P")),
    "mesh_t": ("iu", (-1, -1)), "push_f1": ("f", ("n",)), "push_d0": ("f", ("m",)),
    "push_d1": ("f", ("m",)), "push_f_load": ("f", ("n",)), "push_resultant": ("f", ("m",)),
    "predicted_contact": ("b", ("m",)), "watch_data": ("f", (-1,)), "watch_indices": ("iu", (-1,)),
    "watch_indptr": ("iu", (-1,)), "watch_gaps": ("f", (-1,)), "watch_edge": ("iu", (-1,)),
    "watch_candidate_gaps": ("f", ("m|0",)), "watch_nodes": ("iu", (-1,)), "meta": ("u", (-1,))}
_KINDS = {"f": "floats", "iu": "integers", "b": "booleans", "u": "bytes"}
#: the numbers of the meta record (a scale, a material constant, the push's record)
_NUMBERS = {"scales": ("length", "displacement", "force", "weight"),
            "discretisation": ("load_offset", "E", "nu", "assemble_s"),
            "push": ("offset1", "scale", "offset_load", "load", "target", "delta", "P")}


def _fits(z: dict[str, np.ndarray], meta: dict[str, Any]) -> tuple[int, int]:
    """``(n, m)`` when every stored array and number is of the kind and size :func:`save`
    writes (checked before any is used, so that nothing of a declared size is built first);
    InputError naming the first that is not."""
    if not isinstance(meta.get("scene"), str):
        raise InputError("meta 'scene' is not a name")
    about = meta.get("discretisation")
    records = {"scales": meta.get("scales"), "discretisation": about,
               "push": about.get("push") if isinstance(about, dict) else None}
    for record, names in _NUMBERS.items():
        values = records[record]
        if values is None and record != "scales":
            continue
        if not isinstance(values, dict):
            raise InputError(f"meta {record!r} is not a record")
        for name in names:
            value = values.get(name)
            if not (value is None and record == "push" and name in ("target", "delta", "P")) and \
                    not (isinstance(value, (int, float)) and not isinstance(value, bool)
                         and np.isfinite(value)):
                raise InputError(f"meta {record}.{name} is {value!r}, not a finite number")
        if record == "scales" and min(values[name] for name in names) <= 0:
            raise InputError("meta 'scales' holds a scale that is not positive")
    multiplicity = meta.get("force_multiplicity")
    if not (isinstance(multiplicity, (int, float)) and np.isfinite(multiplicity) and multiplicity > 0):
        raise InputError(f"meta force_multiplicity is {multiplicity!r}, not a positive number")
    if isinstance(about, dict):
        _model_record(about, records["push"])
    required = ["shape", "meta", "f", "d", "weights", "contact_points",
                *(f"{key}_{part}" for key in "KN" for part in ("data", "indices", "indptr"))]
    if isinstance(about, dict):
        required += ["free_dofs", "prescribed", "load_row"]
        required += ["push_f1", "push_d0", "push_d1"] if records["push"] is not None else []
        required += [f"watch_{part}" for part in ("data", "indices", "indptr", "gaps", "edge",
                                                  "candidate_gaps")] if about.get("watch") else []
    missing = [name for name in required if name not in z]
    if missing:
        raise InputError(f"it holds no {missing[0]!r}")
    shape = z["shape"]
    if shape.dtype.kind not in "iu" or shape.shape != (2,) or min(shape) < 0:
        raise InputError(f"'shape' is {shape.tolist()}, not the two sizes n and m")
    sizes = {"n": int(shape[0]), "m": int(shape[1]), "n+1": int(shape[0]) + 1,
             "m+1": int(shape[1]) + 1, "0": 0, "D": z["prescribed"].size if "prescribed" in z
             else -1, "P": z["mesh_p"].shape[-1] if "mesh_p" in z else -1}
    for name in z:
        kinds, expected = _ARRAYS.get(name, ("", ()))
        if not kinds:
            raise InputError(f"{name!r} is not an array ContactProblem.save writes")
        array = z[name]
        if array.dtype.kind not in kinds or array.ndim != len(expected):
            raise InputError(f"{name!r} is a {array.dtype} array of shape {array.shape}, not "
                             f"{len(expected)}-D {_KINDS[kinds]}")
        for axis, size in zip(array.shape, expected):
            allowed = {size} if isinstance(size, int) else {sizes[p] for p in size.split("|")}
            if size != -1 and axis not in allowed:
                raise InputError(f"{name!r} has shape {array.shape}, not the size {size} = "
                                 f"{sizes[size.split('|')[0]]} that 'shape' and the other "
                                 "arrays give")
        if kinds == "f" and name != "contact_points" and not np.all(np.isfinite(array)):
            raise InputError(f"{name!r} holds NaN or inf")
    limits = {"free_dofs": sizes["D"], "mesh_t": sizes["P"]}
    for name, limit in limits.items():
        if name in z and z[name].size and not 0 <= z[name].min() <= z[name].max() < limit:
            raise InputError(f"{name!r} indexes outside 0..{limit - 1}")
    if "mesh_t" in z and z["mesh_t"].shape[0] != z["mesh_p"].shape[0] + 1:
        raise InputError(f"'mesh_t' has {z['mesh_t'].shape[0]} corners per element, not "
                         f"{z['mesh_p'].shape[0] + 1} (a simplex in {z['mesh_p'].shape[0]}D)")
    if records["push"] is not None and not isinstance(records["push"].get("pending"), bool):
        raise InputError("meta push.pending is not true or false")
    return sizes["n"], sizes["m"]


def _model_record(about: dict[str, Any], push: dict[str, Any] | None) -> None:
    """InputError naming the first entry of the model's meta record that no model holds."""
    if not isinstance(about.get("params"), dict):
        raise InputError("meta discretisation.params is not a record")
    if not isinstance(about.get("axisymmetric"), bool):
        raise InputError("meta discretisation.axisymmetric is not true or false")
    if not (about["E"] > 0 and -1 < about["nu"] < 0.5):
        raise InputError(f"meta discretisation holds E = {about['E']!r} and nu = {about['nu']!r}: "
                         "E must be positive and nu in (-1, 0.5)")
    materials = about.get("materials", [])
    if not isinstance(materials, list) or any(not isinstance(m, list) or len(m) != 4
                                              for m in materials):
        raise InputError("meta discretisation.materials is not a list of 4-entry records")
    if push is not None and not push["scale"] > 0:
        raise InputError(f"meta push.scale is {push['scale']!r}, not a positive push")
    if push is not None and push.get("pending") and push.get("target") is None:
        raise InputError("meta push is pending without a target load to match")


def _watch(z: dict[str, np.ndarray], stored: dict[str, Any] | None, dofs: int) -> Watch | None:
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
