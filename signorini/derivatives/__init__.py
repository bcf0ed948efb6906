"""Derivatives of the contact answer: ``implicit`` differentiates the KKT conditions on the
final active set; ``scene`` differentiates a scene's physical outputs by its parameters
(``signorini.derivative``; imported on its own, since it builds scenes)."""

from signorini.derivatives.implicit import Cotangent, Sensitivity, Tangent, jvp, vjp

__all__ = ["Cotangent", "Sensitivity", "Tangent", "jvp", "vjp"]
