"""Judging an answer, never computed by the method that made it.

``kkt`` the KKT certificate and active sets; ``inverse`` what it computes with K⁻¹ (the bound on
the force's error, the duality gap) on a factorisation the method holds; ``curvature`` whether
K is indefinite (the QP has no minimum); ``comparison`` two answers compared (for studies and
cross-checks); ``adequacy`` whether the model was adequate (the boundary beyond the candidates);
``diagnosis`` what makes a problem or an answer wrong (that the problem judged is the problem
given is held with the method's contract, :mod:`signorini.solvers.base`).
"""

from signorini.certification.adequacy import Adequacy
from signorini.certification.diagnosis import diagnose
from signorini.certification.comparison import compare
from signorini.certification.inverse import ForwardError
from signorini.certification.kkt import Certificate, active_set, certificate

__all__ = ["Adequacy", "Certificate", "ForwardError", "active_set", "certificate", "compare",
           "diagnose"]
