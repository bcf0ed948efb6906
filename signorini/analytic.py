"""Analytic references (Johnson, Contact Mechanics, 1985, ch. 4).

An elastic body on a rigid flat has the contact modulus ``E* = E / (1 − ν²)``
(plane strain in 2D).
"""

from __future__ import annotations

import numpy as np


def contact_modulus(E: float, nu: float) -> float:
    """``E* = E / (1 − ν²)`` for an elastic body against a rigid one."""
    return E / (1.0 - nu ** 2)


def hertz_cylinder_half_width(P: float, R: float, E_star: float) -> float:
    """Contact half-width of a cylinder on a flat: ``a = √(4PR / (πE*))`` (P per unit length)."""
    return float(np.sqrt(4.0 * P * R / (np.pi * E_star)))


def hertz_cylinder_load(a: float, R: float, E_star: float) -> float:
    """The load per unit length that gives half-width ``a``: ``P = πE*a² / (4R)``."""
    return float(np.pi * E_star * a ** 2 / (4.0 * R))


def hertz_cylinder_peak(P: float, a: float) -> float:
    """Peak pressure of the cylinder: ``p₀ = 2P / (πa)``."""
    return float(2.0 * P / (np.pi * a))


def hertz_pressure(x: np.ndarray, a: float, p0: float) -> np.ndarray:
    """Hertz's elliptic pressure ``p(x) = p₀ √(1 − x²/a²)`` inside ``|x| < a``, zero outside."""
    x = np.asarray(x, dtype=float)
    return p0 * np.sqrt(np.clip(1.0 - (x / a) ** 2, 0.0, None))
