"""The coordinate maps the convention traps lead to, alone and combined, each with its traps named.

The declared map is q = T (φ − θ0): right for coordinates φ.  The hand model's own
coordinates θ may differ from φ by a trap of each kind at once,

    φ = X θ,   X = D^d·S·R   or   D^d·R·S,   with a zero shift s on the angles,

* R ∈ {𝟙, A, A⁻¹}: absolute vs relative angles (A the difference matrix of consecutive
  angles, θ_rel = A θ_abs; T → T·A when the hand's angles are absolute and the map takes
  them as relative, T·A⁻¹ the reverse);
* S = diag(±1) on any subset of the coordinates: an axis turning the other way.  S·R
  flips the map's coordinates (after the change between absolute and relative angles),
  R·S the hand's (before it): two different maps when R ≠ 𝟙;
* D = diag(π/180 on the angles, 1 elsewhere): the hand's angles behave as degrees;
* s_i ∈ {+π/2, +π, −π/2} on angle i (``SHIFTS``): its zero from the vertical instead of
  the horizontal or the reverse (±π/2), from hanging instead of upright (π);
* the offsets θ0 written in degrees: θ0v is θ0 with all its non-zero angle entries, or
  one of them among radians, read as degrees (×π/180);
* alone, P a permutation of coordinates of the same kinds: the hand lists the joints in another
  order (``_orders``, up to ``ORDER_UP_TO_DOF`` coordinates), T' = T·P, θ0' = P⁻¹θ0.

The map the traps lead to is

    T' = T·X,   θ0' = X⁻¹ (θ0v + s)   (θ0 in the map's coordinates φ: the hand's are off),
           or   θ0' = θ0v + X⁻¹ s     (θ0 in the hand's coordinates: T is off),

one map when θ0v = 0.  Quarter turns k ∈ {0, 1, 2, 3} cover every zero a multiple of
π/2 away, a revolute joint being 2π-periodic; for the same reason two candidates are one
map when their T' agree and their joint offsets T'θ0' agree modulo 2π on the revolute
joints (exactly on the others).  Each candidate names its traps
(``traps``) and counts what it touches (``touched``: each coordinate flipped, shifted or
read as degrees, and 1 for a change between absolute and relative angles);
``simplicity`` orders explanations, fewer traps first, then fewer touched.
``candidates`` lists each distinct map once, in that order, under its simplest
description, after the declared map itself (no trap).

For n coordinates, a of them angles, that is (5·2ⁿ − 2)·2·4ᵃ maps before duplicates go
(with θ0 = 0; 2ⁿ flips, and the 2ⁿ + 2ⁿ − 1 distinct orders of each of A and A⁻¹ with them,
each with and without degrees, times the shifts): 4 864 for the triple pendulum.  The work
grows as 8ⁿ, so a larger model flips, and shifts, at most ``most_touched`` coordinates at a time
(besides all of them at once, flipped or shifted alike), the largest number that keeps the
count within ``MAX_CANDIDATES`` (3/n of it beyond three coordinates); none one at a time when even
one exceeds it (from 15 coordinates on), and ``left_out`` says what that leaves out.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

SIGN = "axis sign flip"
ABSOLUTE_RELATIVE = "absolute vs relative angles"
DEGREES = "degrees vs radians"
QUARTER = "vertical vs horizontal zero"
HALF = "upright vs hanging zero"
ORDER = "joint order"
PIVOT = "pivot inertia"

#: the zero shift s of k quarter turns, k = 0..3 (the map's θ0 moves by s)
SHIFTS = (0.0, math.pi / 2, math.pi, -math.pi / 2)
DEG = math.pi / 180
#: decimals two maps must agree to, entry by entry, to be one map (a map's entries are O(1)-O(100)
#: sums of a few products of exact small integers, π/180 and multiples of π/2: rounding ~1e-14)
SAME_MAP_DECIMALS = 9
#: the most candidates enumerated for up to three coordinates: enumerating and screening one costs
#: ~45 µs (measured: 21 888 candidates of a triple pendulum with two non-zero offsets in 0.95 s, one
#: core), so 40 000 keep a search under ~2 s.  Every combination fits unless all three offsets are
#: non-zero (then at most two flipped or shifted at a time: 30 400).  A candidate's cost grows about
#: as n (one more body to fit, larger matrices): beyond three coordinates the budget is 3/n of it.
MAX_CANDIDATES = 40_000


@dataclass(frozen=True)
class Candidate:
    """One combination of traps (module docstring) and the map q = T'(θ − θ0') it leads to."""

    flips: tuple[int, ...] = ()
    #: X = R·S (the hand's coordinates flipped) rather than S·R (the map's)
    flip_first: bool = False
    #: +1: T·A (the hand's angles absolute, the map's relative); −1: T·A⁻¹; 0: neither
    relative: int = 0
    angles_in_degrees: bool = False
    #: the coordinates whose θ0 entry is read as degrees
    offsets_in_degrees: tuple[int, ...] = ()
    #: θ0' = X⁻¹ (θ0v + s) (θ0 in the map's coordinates), else θ0v + X⁻¹ s
    map_side_offsets: bool = True
    #: quarter turns k per coordinate (0 on coordinates that are not angles)
    shifts: tuple[int, ...] = ()
    T: np.ndarray = field(default=None, compare=False, repr=False)
    theta0: np.ndarray = field(default=None, compare=False, repr=False)
    #: the hand's coordinates in the map's order: the map's coordinate i is the hand's
    #: ``order[i]`` (() for the declared order)
    order: tuple[int, ...] = ()

    @property
    def traps(self) -> tuple[str, ...]:
        """The short names of its traps (without the pivot inertia, which the screen fits)."""
        out = [ORDER] if self.order else []
        if self.flips:
            out.append(SIGN)
        if self.relative:
            out.append(ABSOLUTE_RELATIVE)
        if self.angles_in_degrees or self.offsets_in_degrees:
            out.append(DEGREES)
        if any(k in (1, 3) for k in self.shifts):
            out.append(QUARTER)
        if 2 in self.shifts:
            out.append(HALF)
        return tuple(out)

    @property
    def touched(self) -> int:
        shifted = sum(1 for k in self.shifts if k)
        degrees = len(self.offsets_in_degrees) + int(self.angles_in_degrees)
        moved = sum(1 for i, j in enumerate(self.order) if i != j)
        return len(self.flips) + int(self.relative != 0) + shifted + degrees + moved

    @property
    def factors(self) -> str:
        """X as a product of its factors, "D·S·A" (``T·`` + this is T')."""
        R = {1: "A", -1: "A⁻¹", 0: ""}[self.relative]
        S = "S" if self.flips else ""
        parts = ["D" if self.angles_in_degrees else "", *((R, S) if self.flip_first else (S, R))]
        parts += ["P"] if self.order else []
        return "·".join(p for p in parts if p)


def difference_matrix(model) -> np.ndarray:
    """A with θ_rel = A θ_abs over the angular coordinates, in order."""
    A = np.eye(model.nv)
    angular = [i for i, a in enumerate(model.angular) if a]
    for prev, cur in itertools.pairwise(angular):
        A[cur, prev] = -1.0
    return A


def _subsets(items, most: int) -> list[tuple[int, ...]]:
    """The subsets of at most ``most`` items, and all of them."""
    items = list(items)
    out = [c for r in range(min(most, len(items)) + 1) for c in itertools.combinations(items, r)]
    return out if len(items) <= most else [*out, tuple(items)]


def _shift_grid(angular: np.ndarray, most: int) -> np.ndarray:
    """Quarter turns k per coordinate: on at most ``most`` angles, or the same on all of them."""
    idx = list(np.flatnonzero(angular))
    rows = []
    for subset in _subsets(idx, most):
        if len(subset) > most:  # all of them, turned alike
            rows += [[k if i in subset else 0 for i in range(len(angular))] for k in (1, 2, 3)]
            continue
        for ks in itertools.product((1, 2, 3), repeat=len(subset)):
            k = dict(zip(subset, ks, strict=True))
            rows.append([k.get(i, 0) for i in range(len(angular))])
    return np.array(rows, dtype=int)


def _subset_count(size: int, most: int, choices: int = 1, whole: int = 1) -> int:
    """How many rows ``_subsets`` (choices = 1, whole = 1) or ``_shift_grid`` (choices = 3: the
    quarter turns of each touched angle, whole = 3: all of them turned alike) gives, counted
    without building them: Σ_{r ≤ most} C(size, r)·choicesʳ, and the whole set's rows beyond."""
    count = sum(math.comb(size, r) * choices**r for r in range(min(most, size) + 1))
    return count + (whole if size > most else 0)


def most_touched(model, theta0) -> int:
    """The largest number of coordinates flipped or shifted at a time that keeps the count of
    candidates within budget (module docstring); 0 when even one at a time does not: then only all
    of them at once, flipped or shifted alike (64 maps, times the offsets' readings and sides).

    The counts are computed, not enumerated: the grid for all n coordinates of a 40-link chain
    has 4⁴⁰ rows."""
    n, angular = model.nv, np.array(model.angular, dtype=bool)
    theta0 = np.asarray(theta0, float)
    readings, sides = len(_offset_readings(model, theta0)), 2 if np.any(theta0) else 1
    budget = MAX_CANDIDATES * min(1.0, 3 / n)
    relative = 2 if angular.sum() >= 2 else 0
    a = int(angular.sum())
    for most in range(n, 0, -1):
        flips = _subset_count(n, most)
        linear = (flips + relative * (2 * flips - 1)) * (2 if angular.any() else 1)
        if linear * _subset_count(a, most, 3, 3) * readings * sides <= budget:
            return most
    return 0


def left_out(model, most: int) -> str:
    """The traps ``candidates`` leaves out when it touches at most ``most`` coordinates, in words
    ("" when it leaves none out)."""
    n = model.nv
    if most >= n:
        return ""
    if most == 0:
        return f"coordinate conventions on some of the {n} coordinates (only on all of them alike)"
    return (
        f"coordinate conventions on more than {most} of the {n} coordinates at a time (unless on all alike)"
    )


def _linear_parts(model, most: int):
    """(flips, flip_first, relative, angles_in_degrees, X) for every linear part X."""
    n, angular = model.nv, np.array(model.angular, dtype=bool)
    R = {0: np.eye(n)}
    if angular.sum() >= 2:
        A = difference_matrix(model)
        R.update({1: A, -1: np.linalg.inv(A)})
    D = np.diag(np.where(angular, DEG, 1.0))
    for flips in _subsets(range(n), most):
        S = np.diag([-1.0 if i in flips else 1.0 for i in range(n)])
        for relative, Rm in R.items():
            for flip_first in (False, True) if relative and flips else (False,):
                L = Rm @ S if flip_first else S @ Rm
                for degrees in (False, True) if angular.any() else (False,):
                    yield flips, flip_first, relative, degrees, (D @ L if degrees else L)


def _offset_readings(model, theta0) -> list[tuple[int, ...]]:
    """The θ0 entries read as degrees: none; all non-zero angle entries; each one of two or more."""
    nonzero = [i for i, a in enumerate(model.angular) if a and theta0[i] != 0]
    out = [()]
    if nonzero:
        out.append(tuple(nonzero))
    if len(nonzero) >= 2:
        out += [(i,) for i in nonzero]
    return out


#: joints listed in another order are searched for models of up to this many coordinates (n! − 1 maps)
ORDER_UP_TO_DOF = 4


def _orders(model, T, theta0) -> list[Candidate]:
    """The declared map with the hand's coordinates in another order, of the same kinds (an angle
    for an angle): joints listed in the wrong order, M[1,1] and M[2,2] trading values.  With the
    map's coordinate i the hand's ``order[i]``, φ = P θ and T' = T·P, θ0' = P⁻¹ θ0."""
    n = model.nv
    if n > ORDER_UP_TO_DOF:
        return []
    out = []
    for order in itertools.permutations(range(n)):
        if order == tuple(range(n)) or any(model.angular[i] != model.angular[j] for i, j in enumerate(order)):
            continue
        P = np.eye(n)[list(order)]
        out.append(Candidate(shifts=(0,) * n, T=T @ P, theta0=P.T @ theta0, order=order))
    return out


def _key(c: Candidate, revolute: np.ndarray) -> bytes:
    """What makes two candidates one map: T' and the joint offsets, as (cos, sin) on revolute joints."""
    offset = c.T @ c.theta0
    parts = [c.T.ravel(), offset[~revolute], np.cos(offset[revolute]), np.sin(offset[revolute])]
    return (np.round(np.concatenate(parts), SAME_MAP_DECIMALS) + 0.0).tobytes()


def candidates(model, T, theta0, revolute) -> list[Candidate]:
    """The declared map (no trap) first, then every distinct map the traps lead to, simplest first.

    ``revolute``: per joint coordinate of q, whether the joint turns (2π-periodic).
    """
    T, theta0 = np.asarray(T, float), np.asarray(theta0, float)
    angular = np.array(model.angular, dtype=bool)
    readings = _offset_readings(model, theta0)
    most = most_touched(model, theta0)
    grid = _shift_grid(angular, most)
    s = np.array(SHIFTS)[grid]  # (G, n)
    found = []
    for flips, flip_first, relative, degrees, X in _linear_parts(model, most):
        X_inv = np.linalg.inv(X)
        for read in readings if not degrees else [()]:
            theta0v = theta0.copy()
            theta0v[list(read)] *= DEG
            for map_side in (True, False):
                theta0s = (theta0v + s) @ X_inv.T if map_side else theta0v + s @ X_inv.T
                for k, th0 in zip(grid, theta0s, strict=True):
                    found.append(
                        Candidate(
                            flips,
                            flip_first,
                            relative,
                            degrees,
                            read,
                            map_side,
                            tuple(int(x) for x in k),
                            T @ X,
                            th0,
                        )
                    )
    found += _orders(model, T, theta0)
    found.sort(key=lambda c: (len(c.traps), c.touched))  # stable: the enumeration order breaks ties
    seen, out = set(), []
    revolute = np.asarray(revolute, dtype=bool)
    for c in found:
        key = _key(c, revolute)
        if key not in seen:
            seen.add(key)
            out.append(c)
    assert not out[0].traps, "the declared map comes first"
    return out
