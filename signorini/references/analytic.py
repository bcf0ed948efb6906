"""Analytic references (Johnson, Contact Mechanics, 1985, ch. 4).

An elastic body on a rigid flat has the contact modulus ``E* = E / (1 − ν²)``
(plane strain in 2D).

The formulas are written so that no intermediate product leaves the range of
the quantities themselves (``P/E*`` is a length in 2D, an area in 3D): a
result that double precision cannot hold comes back infinite or zero, never
as an exception or a warning, and the scenes refuse it by name.
"""

from __future__ import annotations

import numpy as np



def _quiet() -> np.errstate:
    """No warning for an overflow or underflow: the caller checks what comes back."""
    return np.errstate(over="ignore", under="ignore", divide="ignore")


def contact_modulus(E: float, nu: float) -> float:
    """``E* = E / (1 − ν²)`` for an elastic body against a rigid one."""
    return E / (1.0 - nu ** 2)


def hertz_cylinder_half_width(P: float, R: float, E_star: float) -> float:
    """Contact half-width of a cylinder on a flat: ``a = √(4PR / (πE*))`` (P per unit length)."""
    with _quiet():
        return float(np.sqrt(4.0 / np.pi * (np.float64(P) / E_star) * R))


def hertz_cylinder_load(a: float, R: float, E_star: float) -> float:
    """The load per unit length that gives half-width ``a``: ``P = πE*a² / (4R)``."""
    with _quiet():
        return float(np.pi / 4.0 * np.float64(E_star) * (np.float64(a) / R) * a)


def hertz_cylinder_peak(P: float, a: float) -> float:
    """Peak pressure of the cylinder: ``p₀ = 2P / (πa)``."""
    return float(2.0 * P / (np.pi * a))


def hertz_pressure(x: np.ndarray, a: float, p0: float) -> np.ndarray:
    """Hertz's elliptic pressure ``p(x) = p₀ √(1 − x²/a²)`` inside ``|x| < a``, zero outside."""
    x = np.asarray(x, dtype=float)
    return p0 * np.sqrt(np.clip(1.0 - (x / a) ** 2, 0.0, None))


# --- sphere on a flat (Johnson 1985, §4.2, eqs. 4.22–4.24) ----------------------------------


def hertz_sphere_radius(P: float, R: float, E_star: float) -> float:
    """Contact radius of a sphere on a flat: ``a = (3PR / (4E*))^(1/3)`` (P the total load)."""
    with _quiet():
        return float(np.cbrt(0.75 * (np.float64(P) / E_star) * R))


def hertz_sphere_load(a: float, R: float, E_star: float) -> float:
    """The load that gives contact radius ``a``: ``P = 4E*a³ / (3R)``."""
    with _quiet():
        return float(4.0 / 3.0 * np.float64(E_star) * (np.float64(a) / R) * (np.float64(a) * a))


def hertz_sphere_peak(P: float, a: float) -> float:
    """Peak pressure of the sphere: ``p₀ = 3P / (2πa²)``, so that ``∫ p dA = P``."""
    return float(3.0 * P / (2.0 * np.pi * a ** 2))


# --- rigid flat punch on a half-plane (Johnson 1985, ch. 2: the flat punch) ----------------


def punch_pressure(x: np.ndarray, a: float, P: float) -> np.ndarray:
    """Pressure under a rigid flat punch of half-width a: ``p(x) = P / (π √(a² − x²))``.

    Frictionless, plane strain, load P per unit length; singular at the edges
    ``|x| = a`` (infinite there, ``nan`` is returned at and beyond them) and
    ``∫₋ₐᵃ p dx = P``. The smallest value is the centre's ``P / (πa)``.
    """
    x = np.asarray(x, dtype=float)
    inside = np.abs(x) < a
    out = np.full(x.shape, np.nan)
    out[inside] = P / (np.pi * a * np.sqrt(1.0 - (x[inside] / a) ** 2))
    return out


def punch_load_between(x0: float, x1: float, a: float, P: float) -> float:
    """The load carried by ``x0 ≤ x ≤ x1`` under the punch: ``(P/π)(arcsin(x₁/a) − arcsin(x₀/a))``."""
    x0, x1 = np.clip([x0, x1], -a, a)
    return float(P / np.pi * (np.arcsin(x1 / a) - np.arcsin(x0 / a)))


__all__ = ["contact_modulus", "hertz_cylinder_half_width", "hertz_cylinder_load",
           "hertz_cylinder_peak", "hertz_pressure", "hertz_sphere_radius", "hertz_sphere_load",
           "hertz_sphere_peak", "punch_pressure", "punch_load_between"]
