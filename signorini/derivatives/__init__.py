"""Derivatives of the contact answer: ``implicit`` differentiates the KKT conditions on the
final active set; ``scene`` differentiates a scene's physical outputs by its parameters."""

from signorini.derivatives.implicit import Sensitivity, jvp, vjp
from signorini.derivatives.scene import derivative

__all__ = ["Sensitivity", "derivative", "jvp", "vjp"]
