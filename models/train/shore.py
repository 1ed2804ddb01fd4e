"""Shore A <-> Young's modulus, the same maps as tactex-core's `hardness` module (Gent above
Shore A 40, joined smoothly to the ASTM D2240 Shore 00 indenter below), for reporting scores in
Shore A."""

import math

GENT_FROM = 40.0
ZERO_A_IN_00 = 40.0


def _gent_mpa(s):
    return (15.729 + 2.14124 * s) / (100.0 - s)


def _gent_slope(s):
    return 229.853 / ((100.0 - s) ** 2)


def shore_00_to_modulus_mpa(s):
    s = max(s, 0.0)
    force_n = 0.203 + 0.00908 * s
    depth_m = 2.54e-3 * (1.0 - s / 100.0)
    radius_m, nu = 1.19e-3, 0.5
    return 3.0 * (1.0 - nu * nu) * force_n / (4.0 * math.sqrt(radius_m) * depth_m**1.5) * 1e-6


def shore_a_to_modulus_mpa(s):
    s = max(s, 0.0)
    if s >= GENT_FROM:
        return _gent_mpa(s)
    l40 = math.log(_gent_mpa(GENT_FROM))
    k = _gent_slope(GENT_FROM) / _gent_mpa(GENT_FROM)
    l0 = math.log(shore_00_to_modulus_mpa(ZERO_A_IN_00))
    c = (l0 - l40 + GENT_FROM * k) / (GENT_FROM * GENT_FROM)
    x = s - GENT_FROM
    return math.exp(l40 + k * x + c * x * x)


def modulus_to_shore_a(e_mpa):
    """Bisection as in the Rust code: 0 below the scale, towards 100 above."""
    if e_mpa <= shore_a_to_modulus_mpa(0.0):
        return 0.0
    lo, hi = 0.0, 100.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if mid < 100.0 and shore_a_to_modulus_mpa(mid) < e_mpa:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)
