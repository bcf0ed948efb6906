"""Analytic references and the contact pressure compared with them.

``analytic`` Hertz's and the punch's formulas; ``pressure`` nodal forces to pressure and its
comparison; ``catalogue`` the references a scene can declare, by name.
"""
