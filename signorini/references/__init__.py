"""Analytic references and the contact pressure compared with them.

``analytic`` Hertz's and the punch's formulas; ``pressure`` nodal forces to pressure and its
comparison; ``catalogue`` the references a scene can declare, by name.
"""

from signorini.references.analytic import contact_modulus, hertz_pressure
from signorini.references.catalogue import Reference, reference_of
from signorini.references.pressure import ContactProfile, compare_hertz, contact_profile

__all__ = ["ContactProfile", "Reference", "compare_hertz", "contact_modulus", "contact_profile",
           "hertz_pressure", "reference_of"]
