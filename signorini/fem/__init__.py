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
"""

from signorini.fem.assembly import assemble
from signorini.fem.checks import check_model
from signorini.fem.contact_estimate import PressureEstimate
from signorini.fem.estimate import ErrorEstimate, estimate
from signorini.fem.model import CutLoad, FlatObstacle, FlatObstacle3D, SceneModel
from signorini.fem.obstacles import Circle, FlatPunch, HalfPlane, Obstacle, SignedDistance

__all__ = ["Circle", "CutLoad", "ErrorEstimate", "FlatObstacle", "FlatObstacle3D", "FlatPunch",
           "HalfPlane", "Obstacle", "PressureEstimate", "SceneModel", "SignedDistance", "assemble",
           "check_model", "estimate"]
