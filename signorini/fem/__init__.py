"""Finite elements: a scene model in physical units and its assembly into a ContactProblem.

- :mod:`~signorini.fem.model`: :class:`SceneModel` (mesh, material, supports, obstacle, load);
- :mod:`~signorini.fem.obstacles`: rigid obstacles as signed distances (flat, circle, punch);
- :mod:`~signorini.fem.assembly`: P1 stiffness (plane strain, axisymmetric, 3D), gap rows,
  lumped contact weights, non-dimensionalisation and load targeting;
- :mod:`~signorini.fem.estimate`: the a posteriori error estimate in the energy norm (ZZ
  recovery and a contact term), per element;
- :mod:`~signorini.fem.transfer`: P1 fields carried onto a refined mesh (midpoint parents).
"""
