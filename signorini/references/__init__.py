"""Analytic references and the contact pressure compared with them.

``analytic`` Hertz's and the punch's formulas; ``profile`` nodal forces to pressure along the
surface; ``pressure`` its comparison with them; ``catalogue`` the references a scene can declare.
"""

from signorini.references.analytic import contact_modulus, hertz_pressure
from signorini.references.catalogue import Reference, reference_of
from signorini.references.pressure import compare_hertz
from signorini.references.profile import ContactProfile, contact_profile

__all__ = ["ContactProfile", "Reference", "compare_hertz", "contact_modulus", "contact_profile",
           "hertz_pressure", "reference_of"]
