"""The scene families by name, and the analytic reference each declares."""

from __future__ import annotations

from signorini.errors import InputError
from signorini.scenes import block, hertz_cylinder, hertz_sphere, hertz_sphere_3d, punch, reverse_hertz
from signorini.scenes.base import SceneFamily

SCENES: dict[str, SceneFamily] = {f.name: f for f in (hertz_cylinder.FAMILY, block.FAMILY,
                                                     hertz_sphere.FAMILY, hertz_sphere_3d.FAMILY,
                                                     punch.FAMILY, reverse_hertz.FAMILY)}


def get_scene(name: str) -> SceneFamily:
    """Look a scene family up by name; unknown names list the known ones."""
    if name not in SCENES:
        raise InputError(f"unknown scene {name!r}: choose one of {', '.join(sorted(SCENES))} "
                         "(or give the path of a .toml scene file)")
    return SCENES[name]


def scene_reference(name: str) -> str:
    """The analytic reference of scene ``name`` ("" for scenes read from mesh files)."""
    return SCENES[name].reference if name in SCENES else ""
