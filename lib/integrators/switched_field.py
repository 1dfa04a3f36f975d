"""The field of the switched closed loop under an angle limit (and an optional force cap),
compiled in numba for :mod:`lib.integrators.switched_compiled`: the reference's kinematics
(circle (27) or eight (28)), the rates of the state under a mode (+1 / -1 smooth on a side
of the switching surface S = {lat = 0, lon < 0}, 0 sliding on it, the Filippov convex
combination) and the event functions watched by the integrator: the switching function
mode * lat + EPS_LAT (or the sliding exits), the clip's kinks |tau| sin(psi -+ beta_max)
and the cap's |tau|^2 - F_max^2. See :class:`lib.integrators.switched.SwitchedLoop` for the
same system written for ``solve_ivp``.
"""

from __future__ import annotations

import math

import numba

__all__ = ["EPS_LAT", "N_EVENTS"]

#: the switching function is watched at mode * lat + EPS_LAT (N)
EPS_LAT = 1e-9
#: number of event functions per mode (switching or exits, two clip kinks, the cap)
N_EVENTS = 4

# layout of the parameter vector P
_M, _I, _A, _C, _CPHI, _KPX, _KPY, _KVX, _KVY, _R, _TH, _KSLIDE, _KIND = range(13)


@numba.njit
def _kin(P, t):
    """Position, velocity, acceleration and jerk of the reference (circle (27) or eight (28))."""
    s = P[_TH] * t
    return _kin_cs(P, math.cos(s), math.sin(s))


@numba.njit
def _kin_cs(P, c1, s1):
    """:func:`_kin` at the phase s = Theta t of cos c1 and sin s1."""
    R, th = P[_R], P[_TH]
    if P[_KIND] == 0.0:
        c, sn = c1, s1
        return (R * c, R * sn, -R * th * sn, R * th * c, -R * th**2 * c, -R * th**2 * sn,
                R * th**3 * sn, -R * th**3 * c)
    c2, s2 = (c1 - s1) * (c1 + s1), 2 * s1 * c1  # cos 2s, sin 2s: one sincos, not two
    return (0.5 * R * s2, R * s1, R * th * c2, R * th * c1, -2 * R * th**2 * s2, -R * th**2 * s1,
            -4 * R * th**3 * c2, -R * th**3 * c1)


@numba.njit
def _field(P, lim, mode, t, s, out, g):
    """Rates of state s under ``mode`` into ``out`` (6,), event functions into ``g`` (4,);
    ``lim`` = (beta_max, cos beta_max, sin beta_max, F_max)."""
    k = P[_TH] * t
    return _field_cs(P, lim, mode, math.cos(k), math.sin(k), math.cos(s[2]), math.sin(s[2]), s, out, g)


@numba.njit
def _field_cs(P, lim, mode, ck, sk, c, sn, s, out, g):
    """:func:`_field` given cos and sin of the reference's phase Theta t (ck, sk) and of the
    heading s[2] (c, sn): a step takes its stages' from its start's
    (:func:`lib.integrators.trig.cos_sin_near`)."""
    bmax, cb, sb, fmax = lim
    m, I, a, cc, cphi = P[_M], P[_I], P[_A], P[_C], P[_CPHI]
    xd, yd, vxd, vyd, axd, ayd, jxd, jyd = _kin_cs(P, ck, sk)
    x, y, vx, vy, w = s[0], s[1], s[3], s[4], s[5]
    tx = m * axd + cc * vx + P[_KVX] * (vxd - vx) + P[_KPX] * (xd - x)
    ty = m * ayd + cc * vy + P[_KVY] * (vyd - vy) + P[_KPY] * (yd - y)
    lat, lon = ty * c - tx * sn, tx * c + ty * sn
    tn = math.sqrt(tx * tx + ty * ty)
    F = min(tn, fmax)
    ksl = P[_KSLIDE]
    # the clip's edges and the cap: kinks of the smooth fields
    g[1] = lat * cb - lon * sb
    g[2] = lat * cb + lon * sb
    g[3] = tx * tx + ty * ty - fmax * fmax if fmax < math.inf else 1.0
    if mode != 0:
        # beta = clip(psi, +-beta_max), psi = atan2(lat, lon) the demand's angle to the axis,
        # continued by mode * 2 pi just across S; its cosine and sine without trigonometry
        if lon < 0 and mode * lat < 0:
            cbe, sbe = cb, mode * sb
        elif lon >= tn * cb and tn > 0:
            cbe, sbe = lon / tn, lat / tn
        else:
            cbe, sbe = cb, (sb if lat >= 0 else -sb)
        ax = (F * (c * cbe - sn * sbe) - cc * vx) / m
        ay = (F * (sn * cbe + c * sbe) - cc * vy) / m
        aw = (a * F * sbe - cphi * w) / I
        g[0] = mode * lat + EPS_LAT
    else:
        apx = (F * (c * cb - sn * sb) - cc * vx) / m
        apy = (F * (sn * cb + c * sb) - cc * vy) / m
        amx = (F * (c * cb + sn * sb) - cc * vx) / m
        amy = (F * (sn * cb - c * sb) - cc * vy) / m
        awp = (a * F * sb - cphi * w) / I
        awm = (-a * F * sb - cphi * w) / I
        rp = _lat_rate(P, s, apx, apy, tx, ty, vxd, vyd, axd, ayd, jxd, jyd, c, sn)
        rm = _lat_rate(P, s, amx, amy, tx, ty, vxd, vyd, axd, ayd, jxd, jyd, c, sn)
        lam = (rm + ksl * lat) / (rm - rp)
        ax = lam * apx + (1 - lam) * amx
        ay = lam * apy + (1 - lam) * amy
        aw = lam * awp + (1 - lam) * awm
        g[0] = rp + ksl * lat
        g[1] = rm + ksl * lat
        g[2] = 1.0  # while sliding beta is the Filippov average, not a clip: no clip kinks
    out[0], out[1], out[2], out[3], out[4], out[5] = vx, vy, w, ax, ay, aw
    return lat, lon


@numba.njit
def _lat_rate(P, s, ax, ay, tx, ty, vxd, vyd, axd, ayd, jxd, jyd, c, sn):
    m, cc = P[_M], P[_C]
    dtx = m * jxd + cc * ax + P[_KVX] * (axd - ax) + P[_KPX] * (vxd - s[3])
    dty = m * jyd + cc * ay + P[_KVY] * (ayd - ay) + P[_KPY] * (vyd - s[4])
    return dty * c - dtx * sn - s[5] * (tx * c + ty * sn)


@numba.njit
def _one_sided(P, lim, t, s):
    """(lon, rate of lat under beta = +beta_max, under beta = -beta_max)."""
    bmax, fmax = lim[0], lim[3]
    m, cc = P[_M], P[_C]
    xd, yd, vxd, vyd, axd, ayd, jxd, jyd = _kin(P, t)
    tx = m * axd + cc * s[3] + P[_KVX] * (vxd - s[3]) + P[_KPX] * (xd - s[0])
    ty = m * ayd + cc * s[4] + P[_KVY] * (vyd - s[4]) + P[_KPY] * (yd - s[1])
    c, sn = math.cos(s[2]), math.sin(s[2])
    F = min(math.hypot(tx, ty), fmax)
    rp = _lat_rate(P, s, (F * math.cos(s[2] + bmax) - cc * s[3]) / m, (F * math.sin(s[2] + bmax) - cc * s[4]) / m,
                   tx, ty, vxd, vyd, axd, ayd, jxd, jyd, c, sn)
    rm = _lat_rate(P, s, (F * math.cos(s[2] - bmax) - cc * s[3]) / m, (F * math.sin(s[2] - bmax) - cc * s[4]) / m,
                   tx, ty, vxd, vyd, axd, ayd, jxd, jyd, c, sn)
    return tx * c + ty * sn, rp, rm

