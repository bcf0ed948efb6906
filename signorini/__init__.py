"""signorini: frictionless contact of an elastic body with a rigid obstacle, as one QP."""

import logging

from signorini.errors import BackendNotInstalled, InputError, SignoriniError, SolverError
from signorini.problem import ContactProblem, ContactSolution, Scales

__version__ = "0.1.0"

logging.getLogger(__name__).addHandler(logging.NullHandler())

__all__ = ["BackendNotInstalled", "ContactProblem", "ContactSolution", "InputError", "Scales",
           "SignoriniError", "SolverError", "__version__"]
