"""Derivatives of the contact answer: ``implicit`` differentiates the KKT conditions on the
final active set; ``scene`` differentiates a scene's physical outputs by its parameters."""
