"""Exact reference solutions used by tests and validation.

Clamped-clamped inextensible elastica (first, symmetric mode): the centerline is one full
wavelength of the inflectional elastica, four quarter-waves of length K(k)/lambda, so with
m = k^2 the end shortening and midpoint height are

    (L - dL) / L = 2 E(m) / K(m) - 1,      H_mid / L = k / K(m),

K and E the complete elliptic integrals of the first and second kind. Both depend on
dL / L only (section 4.1: H_mid is independent of the material).
"""
from __future__ import annotations

import math

from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from ..limits import InputError

#: clamped-clamped Euler loads P L^2 / EI: symmetric (4 pi^2) and antisymmetric (8.18 pi^2) modes
EULER_SYMMETRIC = 4.0 * math.pi**2
EULER_ANTISYMMETRIC = 80.763


def _elastica_modulus(compression_ratio: float) -> float:
    if not 0.0 < compression_ratio < 1.0:
        raise InputError(f"compression_ratio dL/L = {compression_ratio!r} outside the allowed range (0, 1)")
    target = 1.0 - compression_ratio
    # 2E/K - 1 decreases from 1 (m = 0) to -1 (m -> 1)
    return brentq(lambda m: 2.0 * ellipe(m) / ellipk(m) - 1.0 - target, 0.0, 1.0 - 1e-15, xtol=1e-15, rtol=1e-15)


def clamped_elastica_midpoint_height(compression_ratio: float) -> float:
    """H_mid / L of the clamped-clamped inextensible elastica compressed by dL/L."""
    m = _elastica_modulus(compression_ratio)
    return math.sqrt(m) / ellipk(m)


def clamped_elastica_force(compression_ratio: float) -> float:
    """Axial compressive force P L^2 / EI of the clamped elastica: (4 K(m))^2."""
    m = _elastica_modulus(compression_ratio)
    return (4.0 * ellipk(m)) ** 2
