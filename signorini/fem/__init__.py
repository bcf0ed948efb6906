"""Finite elements: a scene model in physical units and its assembly into a ContactProblem.

- :mod:`~signorini.fem.model`: :class:`SceneModel` (mesh, material, supports, obstacle, load);
- :mod:`~signorini.fem.obstacles`: rigid obstacles as signed distances (flat, circle, punch);
- :mod:`~signorini.fem.assembly`: P1 stiffness (plane strain, axisymmetric, 3D), gap rows,
  lumped contact weights, non-dimensionalisation and load targeting;
- :mod:`~signorini.fem.stiffness`: that stiffness in closed form on triangles and tetrahedra,
  summed into K's pattern from the mesh's edges;
- :mod:`~signorini.fem.estimate`: the a posteriori error estimate in the energy norm (ZZ
  recovery and a contact term), per element; :mod:`~signorini.fem.contact_estimate` its contact
  term and the contact pressure's estimate;
- :mod:`~signorini.fem.transfer`: P1 fields carried onto a refined mesh (midpoint parents).

The names below are loaded at first use (``lazy_loader``): a QP given as arrays, which has no
mesh, never loads scikit-fem.
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach(__name__, submodules=["estimate"], submod_attrs={
    "assembly": ["assemble"], "checks": ["check_model"], "contact_estimate": ["PressureEstimate"],
    "estimate": ["ErrorEstimate"], "model": ["CutLoad", "FlatObstacle", "SceneModel"],
    "obstacles": ["Circle", "FlatPunch", "HalfPlane", "Obstacle", "SignedDistance"]})
