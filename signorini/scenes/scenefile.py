"""Scenes written as TOML files: a registered family with its parameters, or a mesh file.

A **family scene** names a family and sets its parameters, grouped in any of
the tables ``[params]``, ``[geometry]``, ``[material]``, ``[load]``,
``[mesh]`` (the grouping is for the reader; every key is a parameter of the
family, see ``signorini scenes``)::

    scene = "hertz-cylinder"
    [material]
    E = 2.1e11
    nu = 0.3
    [geometry]
    R = 0.01
    [load]
    a_over_R = 0.05

A **mesh scene** reads a triangle mesh (Gmsh ``.msh`` or anything meshio reads) whose
boundaries are named by physical groups: see :mod:`signorini.scenes.mesh_scene`.

Errors name the file, the table, key and line (a TOML syntax error always has its line).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from signorini.errors import InputError
from signorini.fem.model import SceneModel
from signorini.scenes.families import SCENES
from signorini.scenes.mesh_scene import mesh_scene
from signorini.scenes.scene_toml import SceneFileContext, read_scene_file
from signorini.scenes.size import check_size

__all__ = ["FAMILY_TABLES", "build_scene_model", "family_scene_values", "read_scene_file"]

#: tables of a family scene whose keys are the family's parameters
FAMILY_TABLES = ("params", "geometry", "material", "load", "mesh")


def build_scene_model(path: str | Path,
                      overrides: dict[str, Any] | None = None) -> tuple[str, SceneModel]:
    """``(scene name, SceneModel)`` of a scene file, with ``--set`` style ``overrides``.

    The scene name is the family's for a family scene (so its analytic
    reference applies) and ``"file:<path>"`` for a mesh scene.
    """
    data, ctx = read_scene_file(path)
    overrides = dict(overrides or {})
    if "scene" in data:
        name, values = _family_values(data, ctx, overrides)
        params = SCENES[name].parse(values)
        check_size(name, params)  # too big for this machine: refused before meshing, as by name
        return name, SCENES[name].build(params, set(values))
    if "mesh" in data and isinstance(data["mesh"], dict) and "file" in data["mesh"]:
        return f"file:{ctx.path}", mesh_scene(data, ctx, overrides)
    raise ctx.error("the file needs either scene = \"<family>\" (see 'signorini scenes') "
                    "or a [mesh] table with file = \"<mesh.msh>\"", None, None)


# --- family scenes --------------------------------------------------------------------------


def family_scene_values(path: str | Path,
                        overrides: dict[str, Any] | None = None) -> tuple[str, dict[str, Any]] | None:
    """``(family, parameter values)`` of a family scene file with ``overrides`` applied (None for
    a mesh scene): what :func:`build_scene_model` builds, for callers that build it themselves."""
    data, ctx = read_scene_file(path)
    return _family_values(data, ctx, dict(overrides or {})) if "scene" in data else None


def _family_values(data: dict[str, Any], ctx: SceneFileContext,
                   overrides: dict[str, Any]) -> tuple[str, dict[str, Any]]:
    name = data["scene"]
    if not isinstance(name, str) or name not in SCENES:
        raise ctx.error(f"{name!r} is not a scene family: choose one of {', '.join(sorted(SCENES))}",
                        None, "scene")
    family = SCENES[name]
    known = {p.name: p for p in family.params}
    values: dict[str, Any] = {}
    origin: dict[str, str] = {}
    for table, content in data.items():
        if table == "scene":
            continue
        if table not in FAMILY_TABLES or not isinstance(content, dict):
            raise ctx.error(f"unknown entry for a family scene: use the tables "
                            f"{', '.join('[' + t + ']' for t in FAMILY_TABLES)}", None, table)
        for key, value in content.items():
            if key not in known:
                raise ctx.error(f"scene {name!r} has no parameter {key!r}: it takes "
                                f"{', '.join(known)}", table, key)
            if key in values:
                raise ctx.error(f"{key} is set twice (also in [{origin[key]}])", table, key)
            if isinstance(value, (dict, list)):
                raise ctx.error(f"must be a number, got a {type(value).__name__}", table, key)
            values[key], origin[key] = value, table
    for key, value in values.items():
        try:
            known[key].parse(value)
        except InputError as exc:
            raise ctx.error(str(exc), origin[key], key) from None
    values.update(overrides)
    return name, values
