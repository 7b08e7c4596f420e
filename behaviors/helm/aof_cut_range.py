"""AOF_CutRangeCPA: how well each (course, speed) closes on a moving point within a time on leg.

For ownship on course c at speed v and a point moving at (cnh, cnv), ``cpa`` is the closest approach within
``tol`` seconds and ``roc`` the rate of closure now. The utility is ``0.15·nroc + 0.85·metric`` with
``metric = 100·(1 − cpa/d0)`` (d0 the current distance) and ``nroc`` the rate of closure scaled to 0..100 between
the lowest and highest rates over all headings at the domain's top speed (MOOS-IvP's AOF_CutRangeCPA with its
default patience, and CPAEngine's algebra). BHV_Trail uses it outside ``nm_radius``.
"""

from __future__ import annotations

import math

from .ivp import IvPDomain

PATIENCE = 0.85  # AOF_CutRangeCPA's patience 100, clamped to 0.85


def cut_range_table(domain: IvPDomain, osx: float, osy: float, cnx: float, cny: float, cnh: float,
                    cnv: float, tol: float) -> list[list[float]] | None:
    """Utilities ``rows[i][j]`` for course grid value i and speed grid value j; None when ownship is on the point
    or ``tol < 1`` (AOF_CutRangeCPA refuses to initialise then)."""
    px, py = osx - cnx, osy - cny  # ownship relative to the point
    d0 = math.hypot(px, py)
    if d0 <= 0 or tol < 1:
        return None
    rad = math.radians(cnh)
    vcx, vcy = cnv * math.sin(rad), cnv * math.cos(rad)
    ux, uy = -px / d0, -py / d0  # unit vector ownship -> point
    cn_closing = -(vcx * ux + vcy * uy)  # the point's own speed toward ownship
    courses = [(math.sin(math.radians(c)), math.cos(math.radians(c))) for c in domain.vars["course"].grid()]
    speeds = domain.vars["speed"].grid()
    vmax = domain.vars["speed"].high
    rocs = [vmax * (s * ux + c * uy) + cn_closing for s, c in
            ((math.sin(math.radians(h)), math.cos(math.radians(h))) for h in range(360))]
    roc_min, roc_span = min(rocs), max(rocs) - min(rocs)
    roc_scale = 100.0 / roc_span if roc_span > 0 else 0.0
    rows = []
    for sin_c, cos_c in courses:
        row: list[float] = []
        append = row.append
        for v in speeds:
            wx, wy = v * sin_c - vcx, v * cos_c - vcy  # ownship velocity relative to the point
            pw = px * wx + py * wy
            ww = wx * wx + wy * wy
            if pw >= 0 or ww == 0:  # opening (or standing still relative to it): the closest approach is now
                metric = 0.0
            else:
                t = -pw / ww
                if t > tol:
                    t = tol
                dx, dy = px + wx * t, py + wy * t
                metric = 100.0 - 100.0 * math.sqrt(dx * dx + dy * dy) / d0
            nroc = (-pw / d0 - roc_min) * roc_scale
            append((1.0 - PATIENCE) * nroc + PATIENCE * metric)
        rows.append(row)
    return rows
