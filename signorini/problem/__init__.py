"""The QP a method solves, in the units it was given, and what comes back.

``contact`` holds :class:`ContactProblem` (K, f, N, d and what reads the answer);
``solution`` what a method returns; ``scales`` a method's private dimensionless view;
``files`` and ``saved`` a problem read from or written to a file.
"""
