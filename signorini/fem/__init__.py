"""Finite elements: a scene model in physical units and its assembly into a ContactProblem.

- :mod:`~signorini.fem.model`: :class:`SceneModel` (mesh, material, supports, obstacle, load);
- :mod:`~signorini.fem.obstacles`: rigid obstacles as signed distances (flat, circle, punch);
- :mod:`~signorini.fem.assembly`: P1 stiffness (plane strain, axisymmetric, 3D), gap rows,
  lumped contact weights, non-dimensionalisation and load targeting.
"""
