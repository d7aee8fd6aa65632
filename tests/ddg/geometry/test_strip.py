"""Tests of the strip's geometry, material and loading protocol (ddg/geometry/strip.py).

Derived stiffnesses of a rectangular cross-section W x b, the paper's scene built from
ratios, the shear limit of Eq. (B.1), and input validation: every bad input raises
ddg.InputError (a ValueError) with a one-line message naming the bad value and the allowed
range.
"""
from __future__ import annotations

import dataclasses
import math
import re

import pytest

import ddg
from ddg import InputError, LoadingProtocol, Strip, shear_limit
from ddg.geometry.centerline import MIN_NODES, Centerline

L, W, B, E, NU = 0.12, 0.009, 0.0003, 3.5e9, 0.34


# --------------------------------------------------------------------------- stiffnesses
def test_stiffnesses_of_a_rectangular_cross_section():
    """EA = E W b, EI1 = E b W^3/12 (in plane), EI2 = E W b^3/12 (out of plane),
    GJ = G W b^3/3 with G = E / (2 (1 + nu))."""
    s = Strip(length=L, width=W, thickness=B, young_modulus=E, poisson_ratio=NU)
    assert s.stretching_stiffness == pytest.approx(E * W * B, rel=1e-15)
    assert s.geodesic_bending_stiffness == pytest.approx(E * B * W**3 / 12, rel=1e-15)
    assert s.bending_stiffness == pytest.approx(E * W * B**3 / 12, rel=1e-15)
    assert s.shear_modulus == pytest.approx(E / (2 * (1 + NU)), rel=1e-15)
    assert s.twisting_stiffness == pytest.approx(E / (2 * (1 + NU)) * W * B**3 / 3, rel=1e-15)
    # the in-plane bending is stiffer than the out-of-plane one by (W / b)^2
    assert s.geodesic_bending_stiffness / s.bending_stiffness == pytest.approx((W / B) ** 2, rel=1e-14)
    assert s.twisting_stiffness / s.bending_stiffness == pytest.approx(2 / (1 + NU), rel=1e-14)


def test_twisting_stiffness_is_twice_the_bending_stiffness_at_zero_poisson_ratio():
    """GJ = E/2 W b^3/3 = 2 E W b^3/12 = 2 EI2 when nu = 0 (the paper's default)."""
    s = Strip(length=L, width=W, thickness=B, young_modulus=E, poisson_ratio=0.0)
    assert s.twisting_stiffness == pytest.approx(2 * s.bending_stiffness, rel=1e-15)


def test_derived_scales():
    """Slenderness L/b, width ratio W/L, Euler load 4 pi^2 EI2 / L^2 and force unit E b^3 / L."""
    s = Strip(length=L, width=W, thickness=B, young_modulus=E, poisson_ratio=NU)
    assert s.slenderness == pytest.approx(L / B, rel=1e-15)
    assert s.width_ratio == pytest.approx(W / L, rel=1e-15)
    assert s.euler_load == pytest.approx(4 * math.pi**2 * E * W * B**3 / 12 / L**2, rel=1e-15)
    assert s.force_unit == pytest.approx(E * B**3 / L, rel=1e-15)


def test_strip_is_an_immutable_value():
    s = Strip(length=L, width=W, thickness=B)
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.width = 2 * W  # type: ignore[misc]


def test_limits_of_the_allowed_ranges_are_accepted():
    """W = L, nu = 0 and nu just below 1/2 are valid."""
    assert Strip(length=L, width=L, thickness=B).width == L
    assert Strip(length=L, width=W, thickness=B, poisson_ratio=0.0).poisson_ratio == 0.0
    assert Strip(length=L, width=W, thickness=B, poisson_ratio=0.4999).poisson_ratio == 0.4999


# --------------------------------------------------------------------------- paper scene
@pytest.mark.parametrize(
    "compression_ratio, length, slenderness",
    [(0.5, 0.150, 1181.1), (0.25, 0.100, 787.4)],
)
def test_paper_scene_from_ratios(compression_ratio, length, slenderness):
    """Clamps end 75 mm apart after compression: L = 75 mm / (1 - dL/L); default shim stock
    b = 0.127 mm, so L/b = 1181 at dL/L = 1/2 and 787 at dL/L = 1/4; W = (W/L) L."""
    s = Strip.from_ratios(width_ratio=0.05, compression_ratio=compression_ratio)
    assert s.length == pytest.approx(length, rel=1e-14)
    assert s.length * (1 - compression_ratio) == pytest.approx(75e-3, rel=1e-14)
    assert s.thickness == pytest.approx(0.127e-3, rel=1e-15)
    assert s.width == pytest.approx(0.05 * length, rel=1e-14)
    assert s.slenderness == pytest.approx(slenderness, abs=0.05)
    assert s.young_modulus == 100e9 and s.poisson_ratio == 0.0


def test_from_ratios_with_explicit_slenderness_and_material():
    """slenderness sets b = L / (L/b); material keywords are passed through."""
    s = Strip.from_ratios(0.1, 0.5, slenderness=500, young_modulus=2e9, poisson_ratio=0.3)
    assert s.length == pytest.approx(0.15, rel=1e-14)
    assert s.thickness == pytest.approx(0.15 / 500, rel=1e-14)
    assert s.slenderness == pytest.approx(500, rel=1e-14)
    assert s.width == pytest.approx(0.015, rel=1e-14)
    assert (s.young_modulus, s.poisson_ratio) == (2e9, 0.3)


# --------------------------------------------------------------------------- shear limit
def test_shear_limit_eq_B1():
    """dW_max = sqrt(L^2 + W^2 - (L - dL)^2) - W; the paper's scene W/L = 1/20, dL/L = 1/2
    gives dW_max/L = sqrt(1.0025 - 0.25) - 0.05 = 0.81747."""
    assert shear_limit(1.0, 0.05, 0.5) == pytest.approx(math.sqrt(1.0 + 0.05**2 - 0.5**2) - 0.05, rel=1e-15)
    assert shear_limit(1.0, 0.05, 0.5) == pytest.approx(0.817468, abs=1e-6)
    assert shear_limit(L, W, 0.3 * L) == pytest.approx(math.sqrt(L**2 + W**2 - (0.7 * L) ** 2) - W, rel=1e-15)
    s = Strip(length=L, width=W, thickness=B)
    assert s.shear_limit(0.3 * L) == shear_limit(L, W, 0.3 * L)


def test_shear_limit_geometry():
    """No compression, no room to shear; full compression, the generator spans the plate
    diagonal; dW_max grows with dL and scales with the size of the scene."""
    assert shear_limit(L, W, 0.0) == pytest.approx(0.0, abs=1e-15)
    assert shear_limit(L, W, L) == pytest.approx(math.hypot(L, W) - W, rel=1e-15)
    values = [shear_limit(L, W, f * L) for f in (0.1, 0.25, 0.5, 0.75)]
    assert values == sorted(values)
    assert shear_limit(3 * L, 3 * W, 3 * 0.4 * L) == pytest.approx(3 * shear_limit(L, W, 0.4 * L), rel=1e-14)


def test_loading_protocol_resolves_shear_to_the_limit_by_default():
    """shear_ratio=None means dW/L up to dW_max/L; values up to the limit are kept."""
    strip = Strip.from_ratios(0.05, 0.5)
    limit = shear_limit(strip.length, strip.width, 0.5 * strip.length) / strip.length
    assert LoadingProtocol(0.5).resolved_shear_ratio(strip) == pytest.approx(limit, rel=1e-15)
    assert LoadingProtocol(0.5, shear_ratio=0.55).resolved_shear_ratio(strip) == 0.55
    assert LoadingProtocol(0.5, shear_ratio=limit).resolved_shear_ratio(strip) == limit
    assert LoadingProtocol(0.5, shear_ratio=0.0).resolved_shear_ratio(strip) == 0.0


# --------------------------------------------------------------------------- input validation
def test_input_error_is_a_value_error():
    assert issubclass(InputError, ValueError)
    assert ddg.InputError is InputError


def _strip(**changes):
    kwargs = dict(length=L, width=W, thickness=B, young_modulus=E, poisson_ratio=NU)
    kwargs.update(changes)
    return lambda: Strip(**kwargs)


PAPER = Strip.from_ratios(0.05, 0.5)  # dW_max/L = 0.817468

# (description, call, fragments the message must contain: the bad value and the allowed range)
INVALID = [
    ("negative length", _strip(length=-0.1), ["length = -0.1", "positive"]),
    ("zero length", _strip(length=0.0), ["length = 0.0", "positive"]),
    ("non-finite width", _strip(width=float("nan")), ["width = nan", "positive finite"]),
    ("infinite thickness", _strip(thickness=float("inf")), ["thickness = inf", "positive finite"]),
    ("negative thickness", _strip(thickness=-1e-4), ["thickness = -0.0001", "positive"]),
    ("zero Young modulus", _strip(young_modulus=0), ["young_modulus = 0.0", "positive"]),
    ("non-numeric Young modulus", _strip(young_modulus="stiff"), ["young_modulus = 'stiff'", "positive"]),
    ("width above length", _strip(width=0.2), ["W = 0.2", "L = 0.12", "0 < W <= L"]),
    ("thickness equal to width", _strip(thickness=W), ["b = 0.009", "0 < b < W"]),
    ("thickness above width", _strip(thickness=0.02), ["b = 0.02", "0 < b < W"]),
    ("Poisson ratio 1/2", _strip(poisson_ratio=0.5), ["poisson_ratio = 0.5", "[0, 0.5)"]),
    ("negative Poisson ratio", _strip(poisson_ratio=-0.1), ["poisson_ratio = -0.1", "[0, 0.5)"]),
    ("non-finite Poisson ratio", _strip(poisson_ratio=float("nan")), ["poisson_ratio = nan", "[0, 0.5)"]),
    ("no compression", lambda: Strip.from_ratios(0.05, 0.0), ["dL/L = 0.0", "(0, 1)"]),
    ("full compression", lambda: Strip.from_ratios(0.05, 1.0), ["dL/L = 1.0", "(0, 1)"]),
    ("negative compression", lambda: Strip.from_ratios(0.05, -0.2), ["dL/L = -0.2", "(0, 1)"]),
    ("compression above 1", lambda: Strip.from_ratios(0.05, 1.5), ["dL/L = 1.5", "(0, 1)"]),
    ("width ratio above 1", lambda: Strip.from_ratios(1.5, 0.5), ["W/L = 1.5", "(0, 1]"]),
    ("zero width ratio", lambda: Strip.from_ratios(0.0, 0.5), ["W/L = 0.0", "(0, 1]"]),
    ("negative slenderness", lambda: Strip.from_ratios(0.05, 0.5, slenderness=-3), ["L/b = -3.0", "positive"]),
    ("protocol compression 1", lambda: LoadingProtocol(1.0), ["dL/L = 1.0", "(0, 1)"]),
    ("protocol compression 0", lambda: LoadingProtocol(0.0), ["dL/L = 0.0", "(0, 1)"]),
    ("shear beyond dW_max", lambda: LoadingProtocol(0.5, shear_ratio=0.9).resolved_shear_ratio(PAPER),
     ["dW/L = 0.9", "dW_max/L = 0.817468", "[0, 0.817468]"]),
    ("shear just beyond dW_max",
     lambda: LoadingProtocol(0.5, shear_ratio=0.8175).resolved_shear_ratio(PAPER),
     ["dW/L = 0.8175", "[0, 0.817468]"]),
    ("negative shear", lambda: LoadingProtocol(0.5, shear_ratio=-0.1), ["dW/L = -0.1", ">= 0"]),
    ("zero compression steps", lambda: LoadingProtocol(0.5, compression_steps=0), ["compression_steps = 0", ">= 1"]),
    ("negative shear steps", lambda: LoadingProtocol(0.5, shear_steps=-5), ["shear_steps = -5", ">= 1"]),
    ("fractional shear steps", lambda: LoadingProtocol(0.5, shear_steps=2.5), ["shear_steps = 2.5", "integer >= 1"]),
    ("six nodes", lambda: Centerline(0.1, 6), ["M = 6", f">= {MIN_NODES}"]),
    ("zero nodes", lambda: Centerline(0.1, 0), ["M = 0", f">= {MIN_NODES}"]),
]


@pytest.mark.parametrize("call, fragments", [case[1:] for case in INVALID], ids=[case[0] for case in INVALID])
def test_invalid_input_raises_a_one_line_input_error(call, fragments):
    """Bad input raises InputError naming the offending value and the allowed range, on one line."""
    with pytest.raises(InputError, match=re.escape(fragments[0])) as info:
        call()
    message = str(info.value)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, (fragment, message)


def test_resolution_of_seven_nodes_is_the_smallest_accepted():
    assert MIN_NODES == 7
    assert Centerline(0.1, 7).edges == 6
    with pytest.raises(InputError, match=r"M = 6\b"):
        Centerline(0.1, 6)


def test_compression_ratio_has_one_source():
    """dL/L sets the paper strip's length (Strip.from_ratios: L = 75 mm / (1 - dL/L)) and the loading:
    a protocol with another dL/L is refused before any work, in one line naming both values; a strip
    given by its lengths takes any compression; the check is in every entry (API, CLI, FEM)."""
    strip = Strip.from_ratios(0.05, 0.5)
    assert strip.design_compression_ratio == 0.5
    assert LoadingProtocol(0.5).resolved_shear_ratio(strip) > 0
    with pytest.raises(InputError) as info:
        ddg.simulate(strip, LoadingProtocol(0.25), model="rod")
    text = str(info.value)
    assert "\n" not in text and "0.25" in text and "0.5" in text and "Strip.from_ratios" in text
    free = Strip(length=strip.length, width=strip.width, thickness=strip.thickness)
    assert free.design_compression_ratio is None and free == strip   # the same geometry, compared equal
    assert LoadingProtocol(0.25).resolved_shear_ratio(free) > 0
    with pytest.raises(InputError):
        Strip(length=0.15, width=0.01, thickness=1e-4, design_compression_ratio=1.5)
