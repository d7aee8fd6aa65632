"""The relaxed cross-section: a strip's energy per unit length when its cross-section takes the
shape of least energy (issue 30; the one-dimensional ribbon model of Audoly and Neukirch 2021,
"A one-dimensional model for elastic ribbons: a little stretching makes a big difference", JMPS).

Derivation (written out here because the model is this derivation; the reference above is the
published form of the same long-wavelength reduction). A strip of width W, thickness b, Young's
modulus E, Poisson ratio nu, plate stiffness D = E b^3 / (12 (1 - nu^2)), has centreline strains
that vary slowly along it: the stretch eps, the normal curvature kappa (bending about the width
axis; the rod's kappa_n), the twist tau and the in-plane curvature kappa_g. Across the width,
y in [-W/2, W/2], the cross-section deflects by w(y) normal to the strip. In the long-wavelength
limit the transverse membrane stresses vanish (the long edges are free) and the Foppl-von Karman
strip stores, per unit length,

    U = int { (E b / 2) e(y)^2 + (D / 2) [kappa^2 + w''^2 + 2 nu kappa w'' + 2 (1 - nu) tau^2] } dy,
    e(y) = eps - kappa_g y + tau^2 y^2 / 2 - kappa w(y),

with e the axial strain of the fibre at y: the helix of a twisted strip lengthens its fibres by
tau^2 y^2 / 2 (the trapeze effect, ddg.energies.trapeze) and a fibre lifted by w on a centreline
of curvature kappa shortens by kappa w. The centreline is the cross-section's centroid and the
material frame its mean orientation, int w dy = int y w dy = 0. The odd part of w then relieves
nothing (kappa_g keeps the rod's E b W^3 / 12) and the even part solves the linear boundary value
problem

    D w'''' + E b kappa^2 w = E b kappa (e-independent load) + const,  w'' = -nu kappa,  w''' = 0 at y = +-W/2,

in closed form (beam on an elastic foundation of modulus E b kappa^2). With k^4 = 3 (1 - nu^2)
kappa^2 W^4 / b^2 the least energy is

    U = (E b W / 2) (eps + tau^2 W^2 / 24)^2 + (D W / 2) [(1 - nu^2) kappa^2 + 2 (1 - nu) tau^2]
        + (E b W^5 / 8) Psi(k^4) (nu kappa^2 + tau^2)^2,                                      (R)

    Psi(s) = Phi(k) / k^4,   Phi(k) = 1 - (2 / k) (cosh k - cos k) / (sinh k + sin k),  s = k^4,

Phi being the share of the transverse bending (nu kappa + tau^2 / kappa) that the foundation
forbids: Phi ~ k^4 / 180 for a narrow strip, Phi -> 1 - 2 / k for a wide one. The first two terms
of (R) are the rod's stretching, bending EI = E W b^3 / 12 and twisting GJ = E W b^3 / (6 (1 + nu))
plus the trapeze coupling E b W^3 eps tau^2 / 24 and E b W^5 tau^4 / 1152; the last is this
module's. Its limits:
- k -> 0 (narrow, or kappa -> 0 at an inflection point): Psi -> 1/180, and (R) is the trapeze
  ribbon, E b W^5 tau^4 (1/1152 + 1/1440) = E b W^5 tau^4 / 640 (the cross-section cannot bend
  away the edges' stretching without a curvature to bend against);
- k -> infinity (wide): U -> (D W / 2) (kappa^2 + tau^2)^2 / kappa^2 with eps relaxed, Sadowsky's
  developable ribbon, nu-independent; the bending stiffness of an untwisted strip goes from
  E W b^3 / 12 to D W (the anticlastic, Ashwell, transition);
- tau = 0, nu = 0: the term vanishes with its first derivatives, the rod and the exact elastica.
  For nu > 0 an untwisted strip keeps the anticlastic term (E b W^5 / 8) Psi nu^2 kappa^4.

Discretely (integrated strains as the rod's, kappa -> kappa_i / dl_i, tau -> tau_i / dl_i,
eps -> the Voronoi mean stretch of ddg.energies.stencil_coupling), per interior node

    E_i = C3 eps_i tau_i^2 / dl_i + C5 tau_i^4 / dl_i^3 + A Psi(c kappa_i^2 / dl_i^2) (nu kappa_i^2 + tau_i^2)^2 / dl_i^3,

C3 = E b W^3 / 24, C5 = E b W^5 / 1152, A = E b W^5 / 8, c = 3 (1 - nu^2) W^4 / b^2. Psi is
evaluated by its Taylor series in s below SERIES_BELOW (the closed form cancels there) and by the
closed form, scaled by e^-k so that it holds for any k, above; both with exact first and second
derivatives, so Newton and the stability test see the exact Hessian of (R).
"""
from __future__ import annotations

import numpy as np

__all__ = ["cross_section_coefficients", "cross_section_density", "relaxed_share", "well_bottom", "psi",
           "foundation_share", "SERIES_BELOW"]

#: Taylor coefficients of Psi(s) = sum_n a_n s^n (exact rationals from the series of Phi(k) / k^4,
#: tests/test_cross_section.py re-derives the first ones); the radius of convergence is about
#: s = 125, so at s < SERIES_BELOW = 4 the 14 terms leave a relative error below 1e-20.
_SERIES = np.array([
    1 / 180, -1 / 22680, 2879 / 8172964800, -3911 / 1389404016000,
    74070881 / 3292970882160960000, -226894807 / 1262305504828368000000,
    1.4363508775581876e-15, -1.1477862247352584e-17, 9.171945645653379e-20,
    -7.329290517165085e-22, 5.8568270637827055e-24, -4.68018332398229e-26,
    3.739928754518298e-28, -2.98857248116756e-30])
SERIES_BELOW = 4.0


def foundation_share(k):
    """Phi(k) = 1 - (2 / k) (cosh k - cos k) / (sinh k + sin k) (k > 0) and its first two
    derivatives in k, each scaled by e^-k so that no term overflows."""
    k = np.asarray(k, dtype=float)
    e = np.exp(-k)
    sh, ch = 0.5 * (1.0 - e * e), 0.5 * (1.0 + e * e)  # e^-k sinh k, e^-k cosh k
    sn, co = e * np.sin(k), e * np.cos(k)
    den = sh + sn
    r = (ch - co) / den
    r1 = 2.0 * sh * sn / den**2
    r2 = 2.0 * e * (ch * np.sin(k) + sh * np.cos(k)) / den**2 - 4.0 * sh * sn * (ch + co) / den**3
    phi = 1.0 - 2.0 * r / k
    phi1 = 2.0 * r / k**2 - 2.0 * r1 / k
    phi2 = -4.0 * r / k**3 + 4.0 * r1 / k**2 - 2.0 * r2 / k
    return phi, phi1, phi2


def psi(s):
    """Psi(s) = Phi(s^(1/4)) / s (s >= 0) and its first and second derivatives in s (arrays)."""
    s = np.asarray(s, dtype=float)
    value, first, second = np.empty_like(s), np.empty_like(s), np.empty_like(s)
    small = s < SERIES_BELOW
    if np.any(small):
        x = s[small]
        n = np.arange(len(_SERIES))
        powers = x[:, None] ** n[None, :]
        value[small] = powers @ _SERIES
        first[small] = (powers[:, :-1] * n[None, 1:]) @ _SERIES[1:]
        second[small] = (powers[:, :-2] * (n[2:] * (n[2:] - 1))[None, :]) @ _SERIES[2:]
    large = ~small
    if np.any(large):
        x = s[large]
        k = x**0.25
        phi, phi1, phi2 = foundation_share(k)
        k1 = 0.25 / k**3          # dk/ds
        k2 = -3.0 / (16.0 * k**7)  # d2k/ds2
        value[large] = phi / x
        first[large] = phi1 * k1 / x - phi / x**2
        second[large] = (phi2 * k1**2 + phi1 * k2) / x - 2.0 * phi1 * k1 / x**2 + 2.0 * phi / x**3
    return value, first, second


def cross_section_coefficients(young_modulus: float, thickness: float, width: float,
                               poisson_ratio: float) -> tuple[float, float, float, float, float]:
    """(C3, C5, G0, c, nu): C3 = E b W^3 / 24, C5 = E b W^5 / 1152, c = 3 (1 - nu^2) W^4 / b^2 and
    G0 = E W b^3 / (24 c), the unit of the scaled density (G0 K^2 is the rod's bending EI kappa^2 / 2)."""
    e, b, w, nu = young_modulus, thickness, width, poisson_ratio
    c = 3.0 * (1.0 - nu * nu) * w**4 / b**2
    return (e * b * w**3 / 24.0, e * b * w**5 / 1152.0, e * w * b**3 / (24.0 * c), c, nu)


def _share_terms(s, t, nu):
    """phi = Psi(s) q^2 / m (q = nu s + T^2, m = 1 - nu^2) and its partials phi_s, phi_ss, phi_T,
    phi_TT, phi_sT at s = K^2 (arrays)."""
    m = 1.0 - nu * nu
    p, p1, p2 = psi(s)
    q = nu * s + t * t
    phi = p * q * q / m
    phi_s = (p1 * q * q + 2.0 * nu * p * q) / m
    phi_ss = (p2 * q * q + 4.0 * nu * p1 * q + 2.0 * nu * nu * p) / m
    phi_t = 4.0 * p * q * t / m
    phi_tt = 4.0 * p * (q + 2.0 * t * t) / m
    phi_st = 4.0 * t * (p1 * q + nu * p) / m
    return phi, phi_s, phi_ss, phi_t, phi_tt, phi_st


def well_bottom(t, nu, iterations: int = 60):
    """s_m = K_m^2 where the scaled bending density K^2 + phi(K^2, T) is least, for each T whose
    density has a double well (1 + phi_s(0, T) < 0); nan elsewhere. Safeguarded Newton on
    h(s) = 1 + phi_s(s, T), which is negative at 0 and tends to 1 / (1 - nu^2) (one root)."""
    t = np.asarray(t, dtype=float)
    out = np.full(t.shape, np.nan)
    h0 = 1.0 + _share_terms(np.zeros_like(t), t, nu)[1]
    well = h0 < 0.0
    if not np.any(well):
        return out
    tw = t[well]
    lo = np.zeros_like(tw)
    hi = np.maximum(tw * tw, 1.0)
    for _ in range(200):  # grow the bracket until h(hi) > 0
        bad = 1.0 + _share_terms(hi, tw, nu)[1] <= 0.0
        if not np.any(bad):
            break
        hi = np.where(bad, 2.0 * hi, hi)
    s = 0.5 * (lo + hi)
    for _ in range(iterations):
        _, phi_s, phi_ss, _, _, _ = _share_terms(s, tw, nu)
        h = 1.0 + phi_s
        lo = np.where(h < 0.0, s, lo)
        hi = np.where(h < 0.0, hi, s)
        step = s - h / phi_ss
        inside = np.isfinite(step) & (step > lo) & (step < hi)
        new = np.where(inside, step, 0.5 * (lo + hi))
        if np.all(np.abs(new - s) <= 1e-15 * np.maximum(new, 1.0)):
            s = new
            break
        s = new
    out[well] = s
    return out


def relaxed_share(k, t, nu, relaxed: bool = True):
    """The scaled density beyond the rod's bending, f(K, T) = phi(K^2, T) (K = sqrt(c) kappa,
    T = sqrt(c) tau), and its partials f_K, f_T, f_KK, f_KT, f_TT (arrays).

    relaxed: where K^2 + phi has a double well in K (strong twist near an inflection point, T
    above about 12.3 for nu = 0) the bending density is replaced by its convex envelope in K,
    flat at the bottom of the well for |K| < K_m (f = K_m^2 + phi(K_m^2, T) - K^2 there); see the
    module docstring."""
    s = k * k
    phi, phi_s, phi_ss, phi_t, phi_tt, phi_st = _share_terms(s, t, nu)
    f = phi
    f_k = 2.0 * k * phi_s
    f_kk = 2.0 * phi_s + 4.0 * s * phi_ss
    f_t = phi_t
    f_kt = 2.0 * k * phi_st
    f_tt = phi_tt
    if relaxed:
        sm = well_bottom(t, nu)
        flat = np.isfinite(sm) & (s < np.nan_to_num(sm, nan=-1.0))
        if np.any(flat):
            smf, tf = sm[flat], t[flat]
            mphi, _, mphi_ss, mphi_t, mphi_tt, mphi_st = _share_terms(smf, tf, nu)
            f = np.where(flat, 0.0, f)
            f[flat] = smf + mphi - s[flat]
            f_k[flat] = -2.0 * k[flat]
            f_kk[flat] = -2.0
            f_kt[flat] = 0.0
            f_t[flat] = mphi_t
            f_tt[flat] = mphi_tt - mphi_st**2 / mphi_ss
    return f, f_k, f_t, f_kk, f_kt, f_tt


def cross_section_density(eps, kappa, tau, voronoi_lengths, coefficients, relaxed: bool = True):
    """E_i per stencil (n,), partials in (eps, kappa_n, tau) (n, 3) and second partials (n, 3, 3).

    eps: the stencils' centreline stretch; kappa, tau: their integrated normal curvature and twist
    (Eqs. 3-5); coefficients from cross_section_coefficients; relaxed: see relaxed_share."""
    c3, c5, g0, c, nu = coefficients
    dl = voronoi_lengths
    root = np.sqrt(c)
    k, t = root * kappa / dl, root * tau / dl
    f, f_k, f_t, f_kk, f_kt, f_tt = relaxed_share(k, t, nu, relaxed)
    t2 = tau * tau
    energy = c3 * eps * t2 / dl + c5 * t2 * t2 / dl**3 + g0 * dl * f
    first = np.empty((len(energy), 3))
    first[:, 0] = c3 * t2 / dl
    first[:, 1] = g0 * root * f_k
    first[:, 2] = 2.0 * c3 * eps * tau / dl + 4.0 * c5 * tau * t2 / dl**3 + g0 * root * f_t
    second = np.zeros((len(energy), 3, 3))
    second[:, 0, 2] = second[:, 2, 0] = 2.0 * c3 * tau / dl
    second[:, 1, 1] = g0 * c * f_kk / dl
    second[:, 1, 2] = second[:, 2, 1] = g0 * c * f_kt / dl
    second[:, 2, 2] = 2.0 * c3 * eps / dl + 12.0 * c5 * t2 / dl**3 + g0 * c * f_tt / dl
    return energy, first, second
