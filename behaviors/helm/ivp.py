"""The IvP domain, ZAIC_PEAK objective functions, and the grid solver (spec §6).

Most behaviours build a separable function (a sum of one-variable pieces), so the weighted sum over behaviours is
maximised one decision variable at a time over that variable's grid. A function that couples two variables (BHV_Trail's
CPA-based approach, AOF_CutRangeCPA) comes as a table over both grids; those two variables are then maximised
together over the product grid, the separable pieces of the other behaviours added in.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

from .errors import ParamError
from .logic import is_number

MAX_DOMAIN_POINTS = 10_000
"""Most points one decision variable may have: the helm scores every point every iteration, so ``course:0:359:1e9``
would exhaust memory; real domains have hundreds (course 360, depth 0:500:501)."""


@dataclass(frozen=True)
class DomainVar:
    name: str
    low: float
    high: float
    points: int
    optional: bool = False

    @cached_property
    def delta(self) -> float:
        return 0.0 if self.points <= 1 else (self.high - self.low) / (self.points - 1)

    @cached_property
    def _grid(self) -> tuple[float, ...]:
        return tuple(self.low + j * self.delta for j in range(self.points))

    def grid(self) -> list[float]:
        return list(self._grid)

    def snap(self, value: float, wrap: bool = False) -> float:
        """The grid value nearest ``value`` (circular for a wrapping variable such as course)."""
        values = self.grid()
        if wrap:
            period = self.high - self.low + self.delta
            return min(values, key=lambda g: abs((value - g + period / 2) % period - period / 2))
        return min(values, key=lambda g: abs(value - g))


class IvPDomain:
    """Decision variables in declaration order (``domain = course:0:359:360`` lines)."""

    def __init__(self) -> None:
        self.vars: dict[str, DomainVar] = {}

    def add(self, spec: str) -> DomainVar:
        """Parse ``name:low:high:npts[:optional]`` or ``name:low:high:delta=D`` (commas allowed too)."""
        fields = [f.strip() for f in spec.replace(",", ":").split(":")]
        if len(fields) < 4:
            raise ParamError(f"domain '{spec}': expected name:low:high:npts")
        name, low_s, high_s, pts_s = fields[:4]
        extra = [f.lower() for f in fields[4:]]
        if not name or not is_number(low_s) or not is_number(high_s):
            raise ParamError(f"domain '{spec}': low and high must be numbers")
        low, high = float(low_s), float(high_s)
        if not (math.isfinite(low) and math.isfinite(high)):
            raise ParamError(f"domain '{spec}': low and high must be finite")
        if pts_s.lower().startswith("delta="):
            step = pts_s.split("=", 1)[1]
            if not is_number(step) or not 0 < float(step) < math.inf:
                raise ParamError(f"domain '{spec}': bad delta")
            count = (high - low) / float(step) + 1
        elif is_number(pts_s) and math.isfinite(float(pts_s)) and float(pts_s).is_integer():
            count = float(pts_s)
        else:
            raise ParamError(f"domain '{spec}': npts must be a whole number")
        if count > MAX_DOMAIN_POINTS:
            raise ParamError(f"domain '{spec}': {count:g} points; at most {MAX_DOMAIN_POINTS} are allowed")
        points = int(count)
        if high < low or points < 1 or (high == low) != (points == 1):
            raise ParamError(f"domain '{spec}': need high >= low, and npts == 1 exactly when high == low")
        if extra and extra != ["optional"]:
            raise ParamError(f"domain '{spec}': unknown option '{':'.join(fields[4:])}'")
        if name in self.vars:
            raise ParamError(f"domain '{spec}': {name} declared twice")
        var = DomainVar(name, low, high, points, bool(extra))
        self.vars[name] = var
        return var

    def has(self, name: str) -> bool:
        return name in self.vars

    def summary(self) -> str:
        """IVPHELM_DOMAIN: ``course,0,359,360:speed,0,4,41``."""
        return ":".join(f"{v.name},{_g(v.low)},{_g(v.high)},{v.points}" for v in self.vars.values())


def _g(value: float) -> str:
    return str(int(value)) if value == int(value) else repr(value)


def zaic_peak(var: DomainVar, summit: float, peakwidth: float, basewidth: float, summitdelta: float,
              minutil: float = 0.0, maxutil: float = 100.0, wrap: bool = False) -> list[float]:
    """ZAIC_PEAK utilities over ``var``'s grid (spec §6), circular distance when ``wrap``."""
    grid = var._grid
    period = var.high - var.low + var.delta
    sd = summitdelta if peakwidth > 0 else 0.0
    peak_slope = sd / peakwidth if peakwidth > 0 else 0.0
    base_top = maxutil - sd
    base_slope = (base_top - minutil) / basewidth if basewidth > 0 else 0.0
    outer = peakwidth + basewidth
    # one pass over the grid: the (circular) distance d to the summit, then the piece it falls in (``for d in
    # [expr]`` is a plain assignment inside a comprehension; the helm builds two or three of these per iteration)
    if wrap:
        out = [maxutil - peak_slope * d if d <= peakwidth else base_top - base_slope * (d - peakwidth) if d <= outer
               else minutil
               for x in grid for e in [abs(x - summit) % period] for d in [e if e <= period - e else period - e]]
    else:
        out = [maxutil - peak_slope * d if d <= peakwidth else base_top - base_slope * (d - peakwidth) if d <= outer
               else minutil for x in grid for d in [abs(x - summit)]]
    if out.count(minutil) == len(out):
        nearest = min(range(len(grid)), key=lambda j: abs(grid[j] - summit))
        out[nearest] = maxutil
    return out


class ZaicPiece:
    """A ZAIC_PEAK piece that builds its utilities only when asked (``values()``, the same list as
    :func:`zaic_peak`, mapped onto [0, ``top``] by :func:`normalise` when ``top`` is set).

    Why: a loiter, station-keep, trail or constant behaviour alone on its variables is the common case, and then the
    solver needs only the piece's best grid index. The utility never rises with the distance to the summit, so the
    best is one of the grid points either side of the summit and the lowest the point farthest from it: a handful of
    points, evaluated with the same arithmetic as the whole list (so the choice is the same, ties included), instead
    of a 360-point list built, normalised and scaled every iteration. Where that argument does not hold (a flat top,
    a summit outside the base, a tiny slope) :meth:`best_index` says None and the solver builds the list.
    """

    __slots__ = ("var", "summit", "peakwidth", "basewidth", "minutil", "maxutil", "wrap", "top", "_sd",
                 "_peak_slope", "_base_top", "_base_slope", "_outer", "_period", "_values", "_lo_hi")

    def __init__(self, var: DomainVar, summit: float, peakwidth: float, basewidth: float, summitdelta: float,
                 minutil: float = 0.0, maxutil: float = 100.0, wrap: bool = False, top: float | None = None) -> None:
        self.var, self.summit, self.wrap, self.top = var, summit, wrap, top
        self.peakwidth, self.basewidth, self.minutil, self.maxutil = peakwidth, basewidth, minutil, maxutil
        self._sd = summitdelta
        sd = summitdelta if peakwidth > 0 else 0.0
        self._peak_slope = sd / peakwidth if peakwidth > 0 else 0.0
        self._base_top = maxutil - sd
        self._base_slope = (self._base_top - minutil) / basewidth if basewidth > 0 else 0.0
        self._outer = peakwidth + basewidth
        self._period = var.high - var.low + var.delta
        self._values: list[float] | None = None
        self._lo_hi: tuple[float, float] | None = None

    def normalised(self, top: float) -> ZaicPiece:
        """This piece mapped onto [0, top] (:func:`normalise`), still unbuilt."""
        return ZaicPiece(self.var, self.summit, self.peakwidth, self.basewidth, self._sd, self.minutil,
                         self.maxutil, self.wrap, top)

    def values(self) -> list[float]:
        """The whole list: :func:`zaic_peak`, then :func:`normalise` when ``top`` is set (built once)."""
        if self._values is None:
            raw = zaic_peak(self.var, self.summit, self.peakwidth, self.basewidth, self._sd, self.minutil,
                            self.maxutil, self.wrap)
            self._values = raw if self.top is None else normalise(raw, self.top)
        return self._values

    def _raw_at(self, j: int) -> float:
        """Grid point ``j`` of :func:`zaic_peak`'s list, by the same arithmetic (before its all-minutil fix)."""
        d = abs(self.var._grid[j] - self.summit)
        if self.wrap:
            e = d % self._period
            d = e if e <= self._period - e else self._period - e
        if d <= self.peakwidth:
            return self.maxutil - self._peak_slope * d
        if d <= self._outer:
            return self._base_top - self._base_slope * (d - self.peakwidth)
        return self.minutil

    def _around(self, position: float) -> list[int]:
        """The grid indices next to ``position`` (two either side: slack for rounding), wrapped or clipped."""
        var = self.var
        n = var.points
        if self.wrap:
            k = math.floor(((position - var.low) % self._period) / var.delta)
            return sorted({(k + i) % n for i in range(-1, 3)})
        k = min(max(math.floor((position - var.low) / var.delta), 0), n - 1)  # a summit outside: its nearest end
        return [j for j in range(k - 1, k + 3) if 0 <= j < n]

    def best_index(self) -> tuple[list[int], list[float], float] | None:
        """Where the maximum must be: grid indices, this piece's values there (the list's, exactly), and the least
        amount by which every other point is lower; None where that does not hold (then build the list)."""
        var = self.var
        slopes = [self._peak_slope] if self.peakwidth > 0 else []
        if self.basewidth > 0:
            slopes.append(self._base_slope)
        step = min(slopes, default=0.0) * var.delta
        if var.points < 4 or not 1e-9 <= step < math.inf:
            return None  # a flat top or base (the first of many equal maxima may be anywhere on it), or no slope at all
        near = self._around(self.summit)
        raw = [self._raw_at(j) for j in near]
        if max(raw) <= self.minutil:
            return None  # the summit is beyond every point's reach: zaic_peak's nearest-point rule applies
        if self.top is None:
            return near, raw, step
        lo_hi = self._extremes(max(raw))
        if lo_hi is None:
            return None
        lo, hi = lo_hi
        span = hi - lo
        return near, [self.top * (u - lo) / span for u in raw], step * self.top / span

    def _extremes(self, hi: float) -> tuple[float, float] | None:
        """min and max of the unnormalised list (``hi``: its maximum), or None when they are equal."""
        if self._lo_hi is None:
            far = self._around(self.summit + self._period / 2) if self.wrap else [0, self.var.points - 1]
            self._lo_hi = (min(self._raw_at(j) for j in far), hi)
        lo, hi = self._lo_hi
        return None if hi == lo else (lo, hi)

    def spread(self) -> float | None:
        """max - min of the (unnormalised) list without building it, or None when unsure."""
        found = self.best_index() if self.top is None else None
        if found is None:
            return None
        lo_hi = self._extremes(max(found[1]))
        return 0.0 if lo_hi is None else lo_hi[1] - lo_hi[0]


Piece = list[float] | ZaicPiece


def zaic_piece(var: DomainVar, summit: float, peakwidth: float, basewidth: float, summitdelta: float,
               minutil: float = 0.0, maxutil: float = 100.0, wrap: bool = False) -> ZaicPiece:
    """:func:`zaic_peak` as a :class:`ZaicPiece`: built only if the solver needs more than its best point."""
    return ZaicPiece(var, summit, peakwidth, basewidth, summitdelta, minutil, maxutil, wrap)


def _normalised(piece: Piece, top: float) -> Piece:
    return piece.normalised(top) if isinstance(piece, ZaicPiece) and piece.top is None else normalise(
        _listed(piece), top)


def _listed(piece: Piece) -> list[float]:
    return piece.values() if isinstance(piece, ZaicPiece) else piece


def normalise(values: list[float], top: float) -> list[float]:
    """Affinely map ``values`` onto [0, top] (OF_Coupler's per-piece normalisation)."""
    lo, hi = min(values), max(values)
    if hi == lo:
        return [0.0] * len(values)
    span = hi - lo
    return [top * (v - lo) / span for v in values]


@dataclass
class ObjectiveFunction:
    """An IvP function times ``pwt``: per variable, utilities on the grid (already weighted), and optionally one
    table ``joint = (var1, var2, rows)`` with ``rows[i][j]`` the utility at var1's i-th and var2's j-th grid value."""

    pwt: float
    pieces: dict[str, Piece] = field(default_factory=dict)
    joint: tuple[str, str, list[list[float]]] | None = None

    @classmethod
    def table(cls, pwt: float, var1: str, var2: str, rows: list[list[float]]) -> ObjectiveFunction:
        """A function of two variables together, normalised to [0, 100] (``ipf->getPDMap()->normalize(0,100)``)."""
        lo = min(min(row) for row in rows)
        hi = max(max(row) for row in rows)
        scale = 100.0 / (hi - lo) if hi > lo else 0.0
        return cls(pwt, joint=(var1, var2, [[(u - lo) * scale for u in row] for row in rows]))

    @classmethod
    def single(cls, pwt: float, var: str, utilities: Piece) -> ObjectiveFunction:
        """A one-variable ZAIC; its 0..100 range is kept (the helm rescales only ranges above 100)."""
        if isinstance(utilities, ZaicPiece):
            spread = utilities.spread()
            if spread is None:
                utilities = utilities.values()
            elif spread > 100:
                utilities = utilities.normalised(100.0)
        if isinstance(utilities, list) and max(utilities) - min(utilities) > 100:
            utilities = normalise(utilities, 100.0)
        return cls(pwt, {var: utilities})

    @classmethod
    def coupled(cls, pwt: float, var1: str, u1: Piece, w1: float,
                var2: str, u2: Piece, w2: float) -> ObjectiveFunction:
        """OF_Coupler: each piece normalised to [0, w]; the weights add to 100."""
        total = w1 + w2
        return cls(pwt, {var1: _normalised(u1, 100.0 * w1 / total), var2: _normalised(u2, 100.0 * w2 / total)})


def solve(domain: IvPDomain, functions: list[ObjectiveFunction]) -> dict[str, float]:
    """Per decision variable (or coupled pair), the grid value maximising Σ pwt·utility; ties go to the lowest
    grid index (of the first variable, then the second, for a pair)."""
    active = [fn for fn in functions if fn.pwt > 0]
    pairs: list[tuple[str, str]] = []
    for fn in active:
        if fn.joint is not None and fn.joint[:2] not in pairs:
            pairs.append(fn.joint[:2])
    coupled = [name for pair in pairs for name in pair]
    if len(coupled) != len(set(coupled)):
        raise ValueError(f"a decision variable is coupled in two different tables: {pairs}")
    decisions: dict[str, float] = {}
    for name, var in domain.vars.items():
        if name in coupled:
            continue
        best = _best_of_one_zaic(name, active)
        if best is None:
            scores = _separable_scores(name, var, active)
            if scores is None:
                continue
            best = scores.index(max(scores))  # the first maximum: lowest index
        decisions[name] = var.low + best * var.delta
    for name1, name2 in pairs:
        var1, var2 = domain.vars[name1], domain.vars[name2]
        total: list[list[float]] | None = None
        for fn in active:
            if fn.joint is not None and fn.joint[:2] == (name1, name2):
                pwt = fn.pwt
                if total is None:
                    total = [[pwt * u for u in row] for row in fn.joint[2]]
                else:
                    total = [[t + pwt * u for t, u in zip(trow, urow, strict=True)]
                             for trow, urow in zip(total, fn.joint[2], strict=True)]
        assert total is not None  # every pair comes from some function's table
        extra1 = _separable_scores(name1, var1, active)
        extra2 = _separable_scores(name2, var2, active)
        if extra1 is not None:
            total = [[t + a for t in row] for row, a in zip(total, extra1, strict=True)]
        if extra2 is not None:
            total = [[t + b for t, b in zip(row, extra2, strict=True)] for row in total]
        row_best = [max(row) for row in total]
        best_i = row_best.index(max(row_best))  # the first maximum: lowest index of var1, then of var2
        best_j = total[best_i].index(row_best[best_i])
        decisions[name1] = var1.low + best_i * var1.delta
        decisions[name2] = var2.low + best_j * var2.delta
    return decisions


def _best_of_one_zaic(name: str, functions: list[ObjectiveFunction]) -> int | None:
    """The best grid index of ``name`` when its only piece is a :class:`ZaicPiece` that can tell it unbuilt: the
    lowest index of the highest ``pwt * value`` among its candidate points (as ``scores.index(max(scores))``)."""
    only: tuple[float, ZaicPiece] | None = None
    for fn in functions:
        piece = fn.pieces.get(name)
        if piece is None:
            continue
        if only is not None or not isinstance(piece, ZaicPiece):
            return None
        only = (fn.pwt, piece)
    if only is None:
        return None
    pwt, piece = only
    found = piece.best_index()
    if found is None:
        return None
    indices, values, margin = found
    scores = [pwt * u for u in values]
    top = max(scores)
    if not all(math.isfinite(score) for score in scores) or not pwt * margin > 1e-9 * max(1.0, abs(top)):
        return None  # every other point is lower, but by too little to be sure after rounding
    return min(j for j, score in zip(indices, scores, strict=True) if score == top)


def _separable_scores(name: str, var: DomainVar, functions: list[ObjectiveFunction]) -> list[float] | None:
    """Σ pwt·piece over the functions with a one-variable piece for ``name``; None if there is none."""
    scores: list[float] | None = None
    for fn in functions:
        found = fn.pieces.get(name)
        if found is None:
            continue
        piece = _listed(found)
        pwt = fn.pwt
        if scores is None:
            scores = [pwt * u for u in piece]
        else:
            scores = [s + pwt * u for s, u in zip(scores, piece, strict=True)]
    return scores
