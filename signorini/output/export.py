"""Export a solved scene for ParaView: the mesh with displacement, stress, gap and pressure.

Written through meshio as VTU (``.vtu``, XML) or legacy VTK (``.vtk``), in
physical units. With P1 elements the displacement gradient is constant on
each element, so the strain ``ε = sym ∇u`` and the stress
``σ = λ tr(ε) I + 2μ ε`` are exact per element (cell data). Plane strain
adds ``σ_zz = λ (ε_xx + ε_yy)``; an axisymmetric (r, z) model adds the hoop
strain ``ε_θθ = u_r / r`` at the element's centroid (and ``σ_θθ`` takes the
place of σ_zz). The nodal (point data) stresses are their projection onto P1
with a lumped mass matrix, i.e. area-weighted averages of the surrounding
elements. Von Mises is ``√(½[(σ₁₁ − σ₂₂)² + (σ₂₂ − σ₃₃)² + (σ₃₃ − σ₁₁)²] + 3(σ₁₂² + σ₂₃² + σ₁₃²))``.

Data written:

- point data ``displacement`` (3 components), ``von_mises_nodal``,
  ``sigma_yy_nodal`` (the nodal projections), ``gap`` (remaining gap
  ``d − Nu`` at contact candidates, NaN elsewhere), ``pressure`` and
  ``contact_force`` (zero off the candidates), ``contact_candidate`` (1 or 0);
- cell data ``von_mises``, ``sigma_xx``, ``sigma_yy``, ``sigma_xy``,
  ``sigma_zz`` (in 3D also ``sigma_yz``, ``sigma_xz``), and for a mesh of two bodies
  ``body`` (1 the slave, 2 the master; each body's stress from its own material).

No point array shares a cell array's name, so ParaView lists each once. The
points are the undeformed (reference) positions: ParaView's *Warp By Vector*
on ``displacement`` shows the deformed body, once (``deformed=True`` writes
the positions ``x + u`` instead, for viewers without that filter; do not warp
those again). In 3D the vertical stress is ``sigma_zz``; ``sigma_yy`` is
always the y component.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

import numpy as np
from skfem.models.elasticity import lame_parameters

from signorini.errors import InputError
from signorini.files import atomic_write, check_output_file
from signorini.fem.contact_estimate import candidate_nodes as mesh_nodes_at
from signorini.fem.stiffness import barycentric_gradients
from signorini.references.profile import contact_profile
from signorini.problem.contact import ContactProblem, ContactSolution

log = logging.getLogger(__name__)

#: file suffix → meshio format
FORMATS = {".vtu": "vtu", ".vtk": "vtk"}
CELL_TYPES = {3: "triangle", 4: "tetra"}


def nodal_displacement(problem: ContactProblem, solution: ContactSolution) -> np.ndarray:
    """Displacement of every mesh node, shape (nodes, dim), in physical units (scikit-fem's
    vector P1 dofs are interleaved: a node's components are neighbours)."""
    full = problem.model.expand(solution.u) * problem.scales.displacement
    return full.reshape(-1, problem.model.mesh.p.shape[0])


def element_gradients(points: np.ndarray, elements: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Gradient of the P1 interpolant of nodal ``values`` on each simplex.

    ``points`` (dim, nodes), ``elements`` (dim + 1, k), ``values`` (nodes, c);
    returns (k, c, dim) with entry ``[e, i, j] = ∂vᵢ/∂x_j`` on element e:
    ``∇v = Σₐ vₐ ∇λₐ`` over the barycentric coordinates' gradients
    (:func:`signorini.fem.stiffness.barycentric_gradients`).
    """
    gradients, _ = barycentric_gradients(points, elements)  # (dim, dim + 1, k)
    return np.einsum("jak,akc->kcj", gradients, values[elements])


def element_stress(problem: ContactProblem, solution: ContactSolution,
                   axisymmetric: bool | None = None) -> np.ndarray:
    """Cauchy stress per element, shape (k, 3, 3), physical units (σ = λ tr ε I + 2μ ε).

    ``axisymmetric`` (default: the problem's ``axisymmetric`` attribute, if
    any) adds the hoop strain ``u_r / r`` at each element's centroid; a 2D
    model is otherwise in plane strain.
    """
    if problem.model.mesh is None:
        raise InputError("stresses need the mesh and the material: this problem has neither")
    E, nu = problem.model.element_materials()  # one per element for several bodies
    lam, mu = (np.reshape(value, (-1, 1, 1)) for value in lame_parameters(E, nu))
    mesh = problem.model.mesh
    points = mesh.p * problem.scales.length
    dim = points.shape[0]
    u = nodal_displacement(problem, solution)
    grad = element_gradients(points, mesh.t, u)
    strain = np.zeros((mesh.t.shape[1], 3, 3))
    strain[:, :dim, :dim] = 0.5 * (grad + np.transpose(grad, (0, 2, 1)))
    if axisymmetric is None:
        axisymmetric = bool(getattr(problem, "axisymmetric", False))
    if axisymmetric and dim == 2:
        r = points[0, mesh.t].mean(axis=0)
        u_r = u[mesh.t, 0].mean(axis=0)
        strain[:, 2, 2] = np.divide(u_r, r, out=np.zeros_like(r), where=r > 0)
    trace = np.trace(strain, axis1=1, axis2=2)
    return lam * trace[:, None, None] * np.eye(3) + 2 * mu * strain


def von_mises(stress: np.ndarray) -> np.ndarray:
    """``√(½[(σ₁₁ − σ₂₂)² + (σ₂₂ − σ₃₃)² + (σ₃₃ − σ₁₁)²] + 3(σ₁₂² + σ₂₃² + σ₁₃²))`` per tensor."""
    s = stress
    normal = (s[:, 0, 0] - s[:, 1, 1]) ** 2 + (s[:, 1, 1] - s[:, 2, 2]) ** 2 + \
        (s[:, 2, 2] - s[:, 0, 0]) ** 2
    shear = s[:, 0, 1] ** 2 + s[:, 1, 2] ** 2 + s[:, 0, 2] ** 2
    return np.sqrt(0.5 * normal + 3.0 * shear)


def project_to_nodes(points: np.ndarray, elements: np.ndarray, cell_values: np.ndarray) -> np.ndarray:
    """Lumped L2 projection of element-wise constants onto P1: measure-weighted nodal averages."""
    _, measure = barycentric_gradients(points, elements)
    total = np.zeros(points.shape[1])
    weighted = np.zeros(points.shape[1])
    for row in elements:
        np.add.at(total, row, measure)
        np.add.at(weighted, row, measure * cell_values)
    return np.divide(weighted, total, out=np.zeros_like(total), where=total > 0)


def candidate_nodes(problem: ContactProblem) -> np.ndarray:
    """The mesh node of each contact candidate (matched by coordinates)."""
    return mesh_nodes_at(problem.model.mesh, problem.contact_points)


def export_mesh(problem: ContactProblem, solution: ContactSolution, *, deformed: bool = False,
                axisymmetric: bool | None = None):
    """The solved scene as a :class:`meshio.Mesh` (physical units; see the module's docstring)."""
    import meshio  # meshio: only when a file is written

    mesh = problem.model.mesh
    if mesh is None:
        raise InputError("the problem carries no mesh to export")
    if not (np.all(np.isfinite(solution.u)) and np.all(np.isfinite(solution.lam))):
        raise InputError(f"the {solution.method} solution has no finite answer "
                         f"({solution.status}): nothing to export")
    dim, count = mesh.p.shape
    cell_type = CELL_TYPES.get(mesh.t.shape[0])
    if cell_type is None:
        raise InputError(f"export writes triangles and tetrahedra, not {mesh.t.shape[0]}-node cells")
    points = mesh.p.T * problem.scales.length
    u = nodal_displacement(problem, solution)
    stress = element_stress(problem, solution, axisymmetric)
    mises = von_mises(stress)
    three = ((0, 0), (0, 3 - dim))  # every vector padded to three components
    profile = contact_profile(problem, solution)
    nodes = candidate_nodes(problem)

    def at_candidates(values, elsewhere=0.0, dtype=float) -> np.ndarray:
        out = np.full(count, elsewhere, dtype=dtype)
        out[nodes] = values
        return out

    reference_points = points.T
    point_data = {
        "displacement": np.pad(u, three),
        "von_mises_nodal": project_to_nodes(reference_points, mesh.t, mises),
        "sigma_yy_nodal": project_to_nodes(reference_points, mesh.t, stress[:, 1, 1]),
        "gap": at_candidates(profile.gap, np.nan), "pressure": at_candidates(profile.pressure),
        "contact_force": at_candidates(profile.force),
        "contact_candidate": at_candidates(1, 0, np.int32),
    }
    components = {"sigma_xx": (0, 0), "sigma_yy": (1, 1), "sigma_zz": (2, 2), "sigma_xy": (0, 1)}
    if dim == 3:
        components.update(sigma_yz=(1, 2), sigma_xz=(0, 2))
    cell_data = {"von_mises": [mises]}
    cell_data.update({name: [stress[:, i, j]] for name, (i, j) in components.items()})
    materials = problem.model.materials
    if materials:
        cell_data["body"] = [np.repeat(np.arange(1, len(materials) + 1, dtype=np.int32),
                                       [material[0] for material in materials])]
    return meshio.Mesh(np.pad(points + (u if deformed else 0.0), three),
                       [(cell_type, mesh.t.T.astype(np.int64))],
                       point_data=point_data, cell_data=cell_data)


def check_vtk_path(path: str | os.PathLike) -> tuple[str, str]:
    """``(absolute path, meshio format)`` of an export target, checked before any work.

    InputError for an empty path, a bad suffix, a directory or a path that
    cannot be written (see :func:`signorini.paths.check_output_file`).
    """
    file_format = FORMATS.get(Path(path).suffix.lower())
    if str(path) and file_format is None:
        raise InputError(f"--vtk {str(path)!r}: the file name must end in "
                         f"{' or '.join(FORMATS)} (VTU is ParaView's XML format)")
    return check_output_file(path, "--vtk"), file_format


def export_vtk(problem: ContactProblem, solution: ContactSolution, path: str | os.PathLike, *,
               deformed: bool = False, axisymmetric: bool | None = None) -> Path:
    """Write the solved scene to ``path`` (``.vtu`` or ``.vtk``) whole or not at all.

    The file is written under a temporary name in the same directory and
    renamed, so an existing file is replaced only by a complete one
    (:func:`signorini.files.atomic_write`).
    """
    import meshio  # only when exporting (start-up)

    target, file_format = check_vtk_path(path)
    data = export_mesh(problem, solution, deformed=deformed, axisymmetric=axisymmetric)
    atomic_write(target, lambda name: meshio.write(name, data, file_format=file_format),
                 suffix=Path(path).suffix)
    log.info("wrote %s (%d points, %d cells)", target, data.points.shape[0], len(data.cells[0].data))
    return Path(target)


__all__ = ["nodal_displacement", "element_gradients", "element_stress", "von_mises",
           "project_to_nodes", "candidate_nodes", "export_mesh", "check_vtk_path", "export_vtk"]
