"""A mesh scene: a triangle mesh read from a file, and the tables that say what happens on its
named boundaries (the format: :mod:`signorini.scenes.scenefile`)::


    [mesh]
    file = "block.msh"          # relative to the scene file
    length_scale = 1.0          # optional; default: the mesh's largest extent
    [material]
    E = 1.0
    nu = 0.3
    [[dirichlet]]               # one table per prescribed displacement
    boundary = "symmetry"       # a physical group, or a line: {x = 0.0} / {y = 1.0}
    component = "x"             # x or y
    value = 0.0
    [contact]
    boundary = "bottom"         # the contact candidates
    [obstacle]
    type = "flat"               # flat (height), half-plane (point, normal),
    height = 0.0                # circle (centre, radius), punch (half_width, corner_radius, ...)
    [load]
    boundary = "top"            # whose reactions make up the applied load
    component = "y"
    multiplicity = 2.0          # copies of the model in the whole body
    target = 0.02               # optional: scale the prescribed displacements to this load

A boundary is a physical group of the mesh's lines, or a line ``{x = c}`` / ``{y = c}``.
"""

from __future__ import annotations

import contextlib
import io
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from signorini.errors import InputError
from signorini.fem.checks import check_mesh
from signorini.fem.model import SceneModel
from signorini.fem.obstacles import Circle, FlatPunch, HalfPlane, ScaledQuery
from signorini.fem.model import CHOICES
from signorini.paths import check_input_file
from signorini.scenes.base import length, poisson_ratio
from signorini.scenes.scene_toml import SceneFileContext

__all__ = ["MESH_SCENE_KEYS", "MESH_SCENE_OVERRIDES", "MeshWithBoundaries", "OBSTACLE_KEYS", "mesh_scene",
           "read_mesh"]

#: the keys each type of obstacle takes
OBSTACLE_KEYS = {"flat": {"type", "height"}, "half-plane": {"type", "point", "normal"},
                 "circle": {"type", "centre", "radius"},
                 "punch": {"type", "half_width", "corner_radius", "height", "centre_x"}}
#: the tables of a mesh scene and the keys each takes
MESH_SCENE_KEYS = {
    "mesh": {"file", "length_scale"},
    "material": {"E", "nu", "volumetric"},
    "dirichlet": {"boundary", "component", "value"},
    "contact": {"boundary"},
    "obstacle": set().union(*OBSTACLE_KEYS.values()),
    "load": {"boundary", "component", "multiplicity", "target"},
}
#: parameters of a mesh scene that ``--set`` may override, and where they live
MESH_SCENE_OVERRIDES = {"E": ("material", "E"), "nu": ("material", "nu"), "P": ("load", "target"),
                        "volumetric": ("material", "volumetric")}
COMPONENTS = {"x": 0, "y": 1}


def _table(data: dict[str, Any], ctx: SceneFileContext, name: str, required: bool = True) -> dict[str, Any]:
    content = data.get(name)
    if content is None:
        if required:
            raise ctx.error(f"the table [{name}] is missing", None, name)
        return {}
    if not isinstance(content, dict):
        raise ctx.error("must be a table", None, name)
    unknown = sorted(set(content) - MESH_SCENE_KEYS[name])
    if unknown:
        raise ctx.error(f"unknown key: [{name}] takes {', '.join(sorted(MESH_SCENE_KEYS[name]))}",
                        name, unknown[0])
    return content


def _number(ctx: SceneFileContext, table: str, content: dict[str, Any], key: str, *, default: Any = None,
            positive: bool = False, index: int = 0) -> float:
    if key not in content:
        if default is None:
            raise ctx.error("is required", table, key, index)
        return default
    value = content[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
        raise ctx.error(f"must be a finite number, got {value!r}", table, key, index)
    if positive and not value > 0:
        raise ctx.error(f"must be > 0, got {value!r}", table, key, index)
    return float(value)


def _vector(ctx: SceneFileContext, table: str, content: dict[str, Any], key: str) -> tuple[float, float]:
    value = content.get(key)
    if not (isinstance(value, list) and len(value) == 2 and
            all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)):
        raise ctx.error(f"must be a list of two numbers like [0.0, 1.0], got {value!r}", table, key)
    return float(value[0]), float(value[1])


def _component(ctx: SceneFileContext, table: str, content: dict[str, Any], index: int = 0) -> int:
    value = content.get("component")
    if value not in COMPONENTS:
        raise ctx.error(f"must be \"x\" or \"y\", got {value!r}", table, "component", index)
    return COMPONENTS[value]


@dataclass
class MeshWithBoundaries:
    """A triangle mesh and its named boundaries as boundary-facet index arrays."""

    mesh: Any
    boundaries: dict[str, np.ndarray]


def read_mesh(path: str | Path) -> MeshWithBoundaries:
    """A scikit-fem triangle mesh from any file meshio reads (Gmsh ``.msh`` included).

    Physical groups of line elements (Gmsh ``$PhysicalNames`` of dimension 1)
    or meshio cell sets become named boundaries: the mesh facets whose two
    nodes are the two nodes of one of the group's lines. Points that no
    triangle uses (Gmsh's geometry points) are dropped; the z coordinate
    must be zero.
    """
    import meshio
    from skfem import MeshTri

    path = Path(path)
    check_input_file(str(path), "mesh file", "give the path of a mesh file (relative to the "
                     "scene file)")  # and refuses a FIFO, which would wait forever
    # .msh is Gmsh's (meshio would also try ANSYS and print its complaint on stdout)
    file_format = "gmsh" if path.suffix.lower() == ".msh" else None
    said = io.StringIO()
    try:  # meshio prints its complaints, and its Gmsh reader may call sys.exit
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            raw = meshio.read(path, file_format=file_format)
    except (Exception, SystemExit) as exc:  # meshio raises many kinds (ReadError, ValueError...)
        detail = said.getvalue().strip().splitlines()[-1:] or [f"{type(exc).__name__}: {exc}"]
        raise InputError(f"mesh file {path} cannot be read by meshio ({detail[0].strip()}): "
                         "give a mesh file meshio reads, e.g. Gmsh .msh (format 2.2 or 4)") from None
    points = np.asarray(raw.points, dtype=float)
    if points.shape[1] == 3:
        if np.any(np.abs(points[:, 2]) > 1e-12 * max(1.0, float(np.max(np.abs(points))))):
            raise InputError(f"mesh file {path}: the mesh is not planar (z ≠ 0): "
                             "only 2D triangle meshes are read")
        points = points[:, :2]
    triangles = [block.data for block in raw.cells if block.type == "triangle"]
    if not triangles:
        kinds = sorted({block.type for block in raw.cells})
        raise InputError(f"mesh file {path} has no triangles (cells: {', '.join(kinds) or 'none'}): "
                         "mesh the surface with 3-node triangles")
    t = np.vstack(triangles)
    check_mesh(points.T, t.T, f"mesh file {path} (nodes counted from 0 in the file's order)")
    used = np.unique(t)
    renumber = np.full(points.shape[0], -1)
    renumber[used] = np.arange(used.size)
    mesh = MeshTri(points[used].T.copy(), renumber[t].T.copy())
    lines = _named_lines(raw)
    edge_index = {tuple(sorted(edge)): i for i, edge in enumerate(mesh.facets.T.tolist())}
    boundaries: dict[str, np.ndarray] = {}
    for name, segments in lines.items():
        segments = renumber[segments]
        if np.any(segments < 0):
            raise InputError(f"mesh file {path}: boundary {name!r} has nodes outside the triangles")
        facets = [edge_index.get(tuple(sorted(s))) for s in segments.tolist()]
        if any(f is None for f in facets):
            raise InputError(f"mesh file {path}: boundary {name!r} has lines that are not "
                             "edges of the triangles")
        boundaries[name] = np.unique(np.array(facets, dtype=np.int64))
    return MeshWithBoundaries(mesh, boundaries)


def _named_lines(raw) -> dict[str, np.ndarray]:
    """Named groups of 2-node lines, as (k, 2) node arrays of the file's numbering."""
    named: dict[str, list[np.ndarray]] = {}
    physical = raw.cell_data.get("gmsh:physical")
    if physical is not None:
        tags = {int(v[0]): k for k, v in raw.field_data.items() if len(v) > 1 and int(v[1]) == 1}
        for block, block_tags in zip(raw.cells, physical):
            if block.type != "line":
                continue
            for tag, name in tags.items():
                chosen = np.asarray(block_tags) == tag
                if np.any(chosen):
                    named.setdefault(name, []).append(block.data[chosen])
    for name, per_block in (getattr(raw, "cell_sets", None) or {}).items():
        for block, index in zip(raw.cells, per_block):
            if block.type == "line" and index is not None and len(index):
                named.setdefault(name, []).append(block.data[np.asarray(index)])
    return {name: np.vstack(parts) for name, parts in named.items()}


def _boundary_nodes(ctx: SceneFileContext, mesh_info: MeshWithBoundaries, table: str,
                    content: dict[str, Any], index: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """``(nodes, facets)`` of the boundary a table names: a group name or ``{x = c}``/``{y = c}``."""
    mesh = mesh_info.mesh
    value = content.get("boundary")
    if isinstance(value, str):
        if value not in mesh_info.boundaries:
            names = ", ".join(sorted(mesh_info.boundaries)) or "none (no physical line groups)"
            raise ctx.error(f"no boundary {value!r} in the mesh: its named boundaries are {names}; "
                            "or select a line with {x = value} or {y = value}", table, "boundary", index)
        facets = mesh_info.boundaries[value]
        return np.unique(mesh.facets[:, facets]), facets
    if isinstance(value, dict) and len(value) == 1 and next(iter(value)) in COMPONENTS:
        axis, level = next(iter(value.items()))
        if isinstance(level, bool) or not isinstance(level, (int, float)):
            raise ctx.error(f"{{{axis} = ...}} needs a number, got {level!r}", table, "boundary", index)
        facets = mesh.boundary_facets()
        extent = float(np.ptp(mesh.p, axis=1).max())
        on = np.abs(mesh.p[COMPONENTS[axis]] - level) <= 1e-9 * extent
        facets = facets[np.all(on[mesh.facets[:, facets]], axis=0)]
        if facets.size == 0:
            raise ctx.error(f"no boundary edge lies on the line {axis} = {level}", table, "boundary",
                            index)
        return np.unique(mesh.facets[:, facets]), facets
    raise ctx.error(f"must name a boundary (a string) or a line like {{y = 0.0}}, got {value!r}",
                    table, "boundary", index)


def _obstacle(ctx: SceneFileContext, content: dict[str, Any]) -> HalfPlane | Circle | FlatPunch:
    kind = content.get("type")
    if kind not in OBSTACLE_KEYS:
        raise ctx.error(f"must be one of {', '.join(OBSTACLE_KEYS)}, got {kind!r}", "obstacle", "type")
    extra = sorted(set(content) - OBSTACLE_KEYS[kind])
    if extra:
        raise ctx.error(f"an obstacle of type {kind!r} takes {', '.join(sorted(OBSTACLE_KEYS[kind]))}",
                        "obstacle", extra[0])
    try:
        if kind == "flat":
            height = _number(ctx, "obstacle", content, "height", default=0.0)
            return HalfPlane((0.0, height), (0.0, -1.0))
        if kind == "half-plane":
            return HalfPlane(_vector(ctx, "obstacle", content, "point"),
                             _vector(ctx, "obstacle", content, "normal"))
        if kind == "circle":
            return Circle(_vector(ctx, "obstacle", content, "centre"),
                          _number(ctx, "obstacle", content, "radius", positive=True))
        return FlatPunch(half_width=_number(ctx, "obstacle", content, "half_width", positive=True),
                         corner_radius=_number(ctx, "obstacle", content, "corner_radius", default=0.0),
                         height=_number(ctx, "obstacle", content, "height", default=0.0),
                         centre_x=_number(ctx, "obstacle", content, "centre_x", default=0.0))
    except InputError as exc:
        if str(exc).startswith("scene file"):
            raise
        raise ctx.error(str(exc), "obstacle", None) from None


def mesh_scene(data: dict[str, Any], ctx: SceneFileContext, overrides: dict[str, Any]) -> SceneModel:
    unknown = sorted(set(data) - set(MESH_SCENE_KEYS))
    if unknown:
        raise ctx.error(f"unknown entry for a mesh scene: use the tables "
                        f"{', '.join('[' + t + ']' for t in MESH_SCENE_KEYS)}", None, unknown[0])
    bad = sorted(set(overrides) - set(MESH_SCENE_OVERRIDES))
    if bad:
        raise InputError(f"a mesh scene file has no parameter {bad[0]!r}: --set takes "
                         f"{', '.join(MESH_SCENE_OVERRIDES)}")
    mesh_table = _table(data, ctx, "mesh")
    material = dict(_table(data, ctx, "material"))
    contact = _table(data, ctx, "contact")
    obstacle_table = _table(data, ctx, "obstacle")
    load = dict(_table(data, ctx, "load"))
    for key, value in overrides.items():
        table, name = MESH_SCENE_OVERRIDES[key]
        if key == "volumetric":  # a word, checked with the file's own value below
            material[name] = value
            continue
        try:
            converted = float(value)
        except (TypeError, ValueError):
            raise InputError(f"--set {key}={value!r} is not a number") from None
        (material if table == "material" else load)[name] = converted

    file_name = mesh_table.get("file")
    if not isinstance(file_name, str) or not file_name:
        raise ctx.error("must be the path of a mesh file (a string)", "mesh", "file")
    mesh_path = Path(file_name) if Path(file_name).is_absolute() else ctx.path.parent / file_name
    try:
        mesh_info = read_mesh(mesh_path)
    except InputError as exc:
        raise ctx.error(str(exc), "mesh", "file") from None
    mesh = mesh_info.mesh
    extent = float(np.ptp(mesh.p, axis=1).max())
    length_scale = _number(ctx, "mesh", mesh_table, "length_scale", default=extent, positive=True)
    if length(length_scale):  # given, or the mesh's extent
        key = "length_scale" if "length_scale" in mesh_table else "file"
        raise ctx.error(f"the length {length_scale:g} must be {length(length_scale)}", "mesh", key)

    E = _number(ctx, "material", material, "E", positive=True)
    nu = _number(ctx, "material", material, "nu")
    problem = poisson_ratio(nu)
    if problem:
        raise ctx.error(f"nu = {nu:g} must be {problem}", "material", "nu")
    volumetric = material.get("volumetric", "auto")
    if volumetric not in CHOICES:
        raise ctx.error(f"volumetric = {volumetric!r} must be one of {', '.join(CHOICES)}",
                        "material", "volumetric")

    entries = data.get("dirichlet")
    if not isinstance(entries, list) or not entries or not all(isinstance(e, dict) for e in entries):
        raise ctx.error("at least one [[dirichlet]] table is needed (K must not be singular)",
                        None, "dirichlet")
    dirichlet = []
    for i, entry in enumerate(entries):
        extra = sorted(set(entry) - MESH_SCENE_KEYS["dirichlet"])
        if extra:
            raise ctx.error("unknown key: [[dirichlet]] takes boundary, component, value",
                            "dirichlet", extra[0], i)
        nodes, _ = _boundary_nodes(ctx, mesh_info, "dirichlet", entry, i)
        dirichlet.append((_component(ctx, "dirichlet", entry, i), nodes,
                          _number(ctx, "dirichlet", entry, "value", index=i)))

    candidates, facets = _boundary_nodes(ctx, mesh_info, "contact", contact)
    candidates = candidates[np.argsort(mesh.p[0, candidates], kind="stable")]
    obstacle = _obstacle(ctx, obstacle_table)

    load_nodes, _ = _boundary_nodes(ctx, mesh_info, "load", load)
    component = _component(ctx, "load", load)
    multiplicity = _number(ctx, "load", load, "multiplicity", default=1.0, positive=True)
    target = _number(ctx, "load", load, "target", positive=True) if "target" in load else None
    if target is not None and not any(c == component and v != 0 for c, _, v in dirichlet):
        raise ctx.error("a target load needs a non-zero prescribed displacement in the load's "
                        "component to scale", "load", "target")
    params = {"file": str(ctx.path), "mesh": str(mesh_path), "E": E, "nu": nu, "P": target,
              "length_scale": length_scale, "multiplicity": multiplicity, "volumetric": volumetric}
    try:  # the model's own checks (signorini.fem.checks), said about the file
        return SceneModel(
            mesh=mesh, E=E, nu=nu, dirichlet=dirichlet, contact_nodes=candidates,
            contact_facets=facets,
            obstacle=ScaledQuery(obstacle, mesh.p[:, candidates].T, length_scale),
            load_dofs=(component, load_nodes), length_scale=length_scale,
            force_multiplicity=multiplicity, target_load=target, params=params)
    except InputError as exc:
        raise ctx.error(str(exc), "obstacle" if "obstacle" in str(exc) else None) from None
