"""The QP a method solves, in the units it was given, and what comes back.

``contact`` holds :class:`ContactProblem` (K, f, N, d and what reads the answer) and what a
method returns (:class:`ContactSolution`, from a :class:`WarmStart`); ``scales`` the units of a dimensionless problem;
``files`` and ``saved`` a problem read from or written to a file.
"""

from signorini.problem.contact import ContactProblem, ContactSolution, WarmStart
from signorini.problem.model import Model, Push, ReferenceData, Watch
from signorini.problem.files import read_problem
from signorini.problem.scales import Scales

__all__ = ["ContactProblem", "ContactSolution", "Model", "Push", "ReferenceData", "Scales",
           "WarmStart", "Watch", "read_problem"]
