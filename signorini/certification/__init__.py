"""Judging an answer, never computed by the method that made it.

``kkt`` the KKT certificate and active sets; ``forward_error`` the bound on the force's error;
``adequacy`` whether the model was adequate (the boundary beyond the candidates);
``diagnosis`` what makes a problem or an answer wrong; ``fingerprint`` that the problem judged
is the problem given.
"""

from signorini.certification.adequacy import Adequacy
from signorini.certification.diagnosis import diagnose
from signorini.certification.fingerprint import Fingerprint
from signorini.certification.forward_error import ForwardError
from signorini.certification.kkt import Certificate, active_set, certificate, compare

__all__ = ["Adequacy", "Certificate", "Fingerprint", "ForwardError", "active_set", "certificate",
           "compare", "diagnose"]
