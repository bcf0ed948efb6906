"""Judging an answer, never computed by the method that made it.

``kkt`` the KKT certificate and active sets; ``forward_error`` the bound on the force's error;
``adequacy`` whether the model was adequate (the boundary beyond the candidates);
``diagnosis`` what makes a problem or an answer wrong; ``fingerprint`` that the problem judged
is the problem given.
"""
