"""Scenes: families of bodies and obstacles by name, scene files, and building their problems.

A scene family is one module with a ``FAMILY = SceneFamily(...)`` that owns what is
known of it (parameters, builder, size model, coarse rule, snapping, reference,
validation cases) and one :func:`register` call.
"""

import lazy_loader

# loaded at first use (lazy_loader): solving a QP given as arrays never loads a scene or a mesher
__getattr__, __dir__, __all__ = lazy_loader.attach(__name__, submodules=["adapt", "build"], submod_attrs={
    "base": ["Case", "Param", "SceneFamily", "scene_params"],
    "build": ["build_problem", "coarse_problem", "coarse_values", "with_load"],
    "families": ["SCENES", "get_scene", "portable_scene", "register", "scene_reference", "unregister"]})
