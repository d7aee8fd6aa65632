"""Strip geometry, material and loading protocol as small validated value objects.

SI units throughout. The scene is that of the paper (section 2, Fig. 2): a strip of
length L, width W and thickness b, clamped at both ends; the clamp at s = L is first
moved toward the other by dL along x (compression), then translated by dW along y
(in-plane shear), up to the shear limit dW_max of Eq. (B.1).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from ..limits import (MAX_RECORDED_STEPS, InputError, check_positive, check_within,  # noqa: F401
                      is_bool, require)

#: Paper defaults (section 2): clamps 75 mm apart after compression, shim stock b = 0.127 mm.
CLAMP_SPAN_AFTER_COMPRESSION = 75e-3
PAPER_THICKNESS = 0.127e-3
PAPER_YOUNG_MODULUS = 100e9

#: Physical ranges checked when a Strip is built (SI). They keep every derived stiffness and
#: energy far inside the float range and the scene inside the models' validity:
#: - length: 1 um to 1 km (energies scale as E b^3 W / L; beyond these the 1e-300..1e300 range
#:   of doubles is approached by products such as E A L^2 only far outside them);
#: - Young's modulus: 1 kPa (soft gels) to 10 TPa (above diamond's 1.2 TPa);
#: - density: 1 to 1e5 kg/m^3 (used by the dynamic solver only);
#: - slenderness L/b: 10 to 1e5. Below 10 the strip is no longer thin (rod and plate theories
#:   need b << L); above 1e5 the stretching-to-bending stiffness ratio of an element,
#:   12 (h/b)^2, exceeds ~1e9 at M = 100 and Newton's residual hits round-off (the paper's
#:   strips are L/b = 787 and 1181).
LENGTH_RANGE = (1e-6, 1e3)
YOUNG_MODULUS_RANGE = (1e3, 1e13)
DENSITY_RANGE = (1.0, 1e5)
SLENDERNESS_RANGE = (10.0, 1e5)
#: dL/L: at least 1e-3 (below it the buckle is a small perturbation of the flat strip, H_mid/L <
#: 0.02, and for thick strips not even past the Euler load, whose shortening is pi^2/3 (b/L)^2);
#: at most 0.9: beyond, the clamped elastica's loop closes on itself (self-contact, not modelled).
COMPRESSION_RATIO_RANGE = (1e-3, 0.9)


def shear_limit(length: float, width: float, compression: float) -> float:
    """Largest lateral clamp translation dW_max, Eq. (B.1).

    dW_max = sqrt(L^2 + W^2 - (L - dL)^2) - W: beyond it the two conical singularities at the
    clamps would have to share a generator longer than the plate diagonal.
    """
    return math.sqrt(length**2 + width**2 - (length - compression) ** 2) - width


@dataclass(frozen=True)
class Strip:
    """Geometry and material of the strip, with the derived stiffnesses of Eqs. (6), (A.1), (11).

    length L, width W, thickness b in metres; young_modulus E in pascals; poisson_ratio nu.
    """

    length: float
    width: float
    thickness: float
    young_modulus: float = PAPER_YOUNG_MODULUS
    poisson_ratio: float = 0.0
    density: float = 1390.0  # polyester shim stock, kg/m^3; used only by the dynamic (Eq. 7) option
    #: dL/L whose scene from_ratios built (L = 75 mm / (1 - dL/L)); the loading protocol must then
    #: compress by the same dL/L (LoadingProtocol.resolved_shear_ratio checks it). None for a strip
    #: given by its lengths, which any compression may load.
    design_compression_ratio: float | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        for name in ("length", "width", "thickness", "young_modulus", "density"):
            object.__setattr__(self, name, check_positive(name, getattr(self, name)))
        if self.design_compression_ratio is not None:
            object.__setattr__(self, "design_compression_ratio", _compression_ratio(self.design_compression_ratio))
        nu = self.poisson_ratio
        if is_bool(nu):
            raise InputError(f"poisson_ratio = {nu!r} is a bool; allowed range [0, 0.5)")
        try:
            nu = float(nu)
        except (TypeError, ValueError, OverflowError):
            raise InputError(f"poisson_ratio = {nu!r} is not a number; allowed range [0, 0.5)") from None
        require(math.isfinite(nu) and 0.0 <= nu < 0.5, f"poisson_ratio = {nu!r} outside the allowed range [0, 0.5)")
        object.__setattr__(self, "poisson_ratio", nu)
        check_within("length L", self.length, *LENGTH_RANGE, " m", "the scene is scale-free: give L in metres")
        check_within("young_modulus E", self.young_modulus, *YOUNG_MODULUS_RANGE, " Pa",
                     "from soft gels to above diamond; the geometry does not depend on E")
        check_within("density", self.density, *DENSITY_RANGE, " kg/m^3", "used by the dynamic solver")
        require(
            self.width <= self.length,
            f"width W = {self.width:g} m exceeds length L = {self.length:g} m; allowed 0 < W <= L",
        )
        require(
            self.thickness < self.width,
            f"thickness b = {self.thickness:g} m must be smaller than width W = {self.width:g} m (0 < b < W)",
        )
        check_within("slenderness L/b", self.length / self.thickness, *SLENDERNESS_RANGE, "",
                     "a thin strip (b << L) whose stretching and bending stiffnesses stay within round-off "
                     "of each other")

    @classmethod
    def from_ratios(
        cls,
        width_ratio: float,
        compression_ratio: float,
        slenderness: float | None = None,
        **material,
    ) -> "Strip":
        """The paper's scene from W/L, dL/L and L/b: clamps end 75 mm apart (section 2).

        L = 75 mm / (1 - dL/L); b = L / slenderness, default b = 0.127 mm.
        """
        compression_ratio = _compression_ratio(compression_ratio)
        width_ratio = _ratio("width_ratio W/L", width_ratio, 0.0, 1.0, upper_inclusive=True)
        length = CLAMP_SPAN_AFTER_COMPRESSION / (1.0 - compression_ratio)
        if slenderness is None:
            thickness = PAPER_THICKNESS
        else:
            slenderness = check_positive("slenderness L/b", slenderness)
            low, high = SLENDERNESS_RANGE
            require(low <= slenderness <= high, f"slenderness L/b = {slenderness:g} outside the allowed range "
                     f"[{low:g}, {high:g}]: a thin strip (b << L) within round-off of double precision")
            thickness = length / slenderness
        return cls(length=length, width=width_ratio * length, thickness=thickness,
                   design_compression_ratio=compression_ratio, **material)

    # --- derived quantities -------------------------------------------------------------
    @property
    def shear_modulus(self) -> float:
        return self.young_modulus / (2.0 * (1.0 + self.poisson_ratio))

    @property
    def stretching_stiffness(self) -> float:
        """EA = E W b (N)."""
        return self.young_modulus * self.width * self.thickness

    @property
    def geodesic_bending_stiffness(self) -> float:
        """EI1 = E b W^3 / 12: bending in the plane of the strip (N m^2)."""
        return self.young_modulus * self.thickness * self.width**3 / 12.0

    @property
    def bending_stiffness(self) -> float:
        """EI2 = E W b^3 / 12: out-of-plane bending (N m^2)."""
        return self.young_modulus * self.width * self.thickness**3 / 12.0

    @property
    def twisting_stiffness(self) -> float:
        """GJ = E / (2 (1 + nu)) W b^3 / 3 (N m^2), Eq. (A.1)."""
        return self.shear_modulus * self.width * self.thickness**3 / 3.0

    @property
    def plate_bending_stiffness(self) -> float:
        """D = E b^3 / 12 (N m), per unit width (Eq. 11b prefactor)."""
        return self.young_modulus * self.thickness**3 / 12.0

    @property
    def slenderness(self) -> float:
        return self.length / self.thickness

    @property
    def width_ratio(self) -> float:
        return self.width / self.length

    @property
    def euler_load(self) -> float:
        """Clamped-clamped Euler buckling load 4 pi^2 EI2 / L^2 (N)."""
        return 4.0 * math.pi**2 * self.bending_stiffness / self.length**2

    @property
    def force_unit(self) -> float:
        """E b^3 / L: forces are reported as F L / (E b^3) (App. E)."""
        return self.young_modulus * self.thickness**3 / self.length

    def shear_limit(self, compression: float) -> float:
        return shear_limit(self.length, self.width, compression)

    def as_dict(self) -> dict:
        return {
            "length": self.length,
            "width": self.width,
            "thickness": self.thickness,
            "young_modulus": self.young_modulus,
            "poisson_ratio": self.poisson_ratio,
            "density": self.density,
            "width_ratio": self.width_ratio,
            "slenderness": self.slenderness,
        }


def _ratio(name: str, value, low: float, high: float, upper_inclusive: bool = False) -> float:
    if is_bool(value):
        raise InputError(f"{name} = {value!r} is a bool, not a number")
    try:
        value = float(value)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{name} = {value!r} is not a number") from None
    upper_ok = value <= high if upper_inclusive else value < high
    bracket = "]" if upper_inclusive else ")"
    require(
        math.isfinite(value) and value > low and upper_ok,
        f"{name} = {value!r} outside the allowed range ({low:g}, {high:g}{bracket}",
    )
    return value


def _compression_ratio(value) -> float:
    """dL/L in COMPRESSION_RATIO_RANGE (see there)."""
    value = _ratio("compression_ratio dL/L", value, 0.0, 1.0)
    low, high = COMPRESSION_RATIO_RANGE
    require(low <= value <= high, f"compression_ratio dL/L = {value!r} outside the allowed range [{low:g}, {high:g}]: "
             "below it the strip is barely buckled, above it the elastica closes on itself "
             "(self-contact, not modelled)")
    return value


@dataclass(frozen=True)
class LoadingProtocol:
    """Quasi-static loading: compress by dL along x, then shear by dW along y (section 2).

    compression_ratio dL/L in (0, 1); shear_ratio is the largest dW/L, in [0, dW_max/L]
    (None: dW_max/L of Eq. B.1); shear_sign +1 or -1 for the direction of the lateral
    translation; compression_steps / shear_steps are the number of recorded equilibria of
    each stage (the solver subdivides them adaptively where needed).
    """

    compression_ratio: float
    shear_ratio: float | None = None
    compression_steps: int = 40
    shear_steps: int = 120
    shear_sign: int = 1

    def __post_init__(self) -> None:
        object.__setattr__(self, "compression_ratio", _compression_ratio(self.compression_ratio))
        for name in ("compression_steps", "shear_steps"):
            value = getattr(self, name)
            require(
                isinstance(value, int) and not is_bool(value) and 1 <= value <= MAX_RECORDED_STEPS,
                f"{name} = {value!r} must be an integer in [1, {MAX_RECORDED_STEPS}] (an integer >= 1; more "
                "recorded steps cost time and add nothing: the solver subdivides where it must)",
            )
        require(not is_bool(self.shear_sign) and self.shear_sign in (1, -1),
                 f"shear_sign = {self.shear_sign!r} must be +1 or -1")
        if self.shear_ratio is not None:
            if is_bool(self.shear_ratio):
                raise InputError(f"shear_ratio = {self.shear_ratio!r} is a bool, not a number")
            try:
                value = float(self.shear_ratio)
            except (TypeError, ValueError, OverflowError):
                raise InputError(f"shear_ratio = {self.shear_ratio!r} is not a number") from None
            require(math.isfinite(value) and value >= 0.0, f"shear_ratio dW/L = {value!r} must be >= 0")
            object.__setattr__(self, "shear_ratio", value)

    def resolved_shear_ratio(self, strip: Strip) -> float:
        """Largest dW/L of the run, checked against the shear limit of Eq. (B.1); and the compression
        against the one the strip was built for (Strip.from_ratios): dL/L has one source."""
        design = strip.design_compression_ratio
        if design is not None:
            require(abs(design - self.compression_ratio) <= 1e-12 * design,
                     f"compression_ratio dL/L = {self.compression_ratio:g} of the loading protocol differs from the "
                     f"dL/L = {design:g} the strip was built for (Strip.from_ratios sets L = 75 mm / (1 - dL/L)); "
                     "give the same value to both, or build the strip with Strip(length=..., width=..., thickness=...)")
        limit = strip.shear_limit(self.compression_ratio * strip.length) / strip.length
        if self.shear_ratio is None:
            return limit
        require(
            self.shear_ratio <= limit * (1.0 + 1e-12),
            f"shear_ratio dW/L = {self.shear_ratio:g} beyond the shear limit dW_max/L = {limit:.6g} "
            f"(Eq. B.1) for W/L = {strip.width_ratio:g}, dL/L = {self.compression_ratio:g}; allowed [0, {limit:.6g}]",
        )
        return self.shear_ratio

    def with_(self, **changes) -> "LoadingProtocol":
        return replace(self, **changes)

    def as_dict(self, strip: Strip | None = None) -> dict:
        out = {
            "compression_ratio": self.compression_ratio,
            "shear_ratio": self.shear_ratio if strip is None else self.resolved_shear_ratio(strip),
            "compression_steps": self.compression_steps,
            "shear_steps": self.shear_steps,
            "shear_sign": self.shear_sign,
        }
        return out
