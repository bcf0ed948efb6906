"""Judging an answer, never computed by the method that made it.

``kkt`` the KKT certificate and active sets; ``duality_gap`` its duality gap on a factorisation the
method holds; ``forward_error`` the bound on the force's error;
``adequacy`` whether the model was adequate (the boundary beyond the candidates);
``diagnosis`` what makes a problem or an answer wrong (that the problem judged is the problem
given is held with the method's contract, :mod:`signorini.solvers.base`).
"""

from signorini.certification.adequacy import Adequacy
from signorini.certification.diagnosis import diagnose
from signorini.certification.forward_error import ForwardError
from signorini.certification.kkt import Certificate, active_set, certificate, compare

__all__ = ["Adequacy", "Certificate", "ForwardError", "active_set", "certificate", "compare",
           "diagnose"]
