"""The syntax of a number in a URDF, as urdfdom reads it exactly.

Used by ``pendverify.robot.strict``, which applies these rules to every numeric attribute:

* one number: the whole attribute is a plain decimal literal
  ``[+-]?(\\d+(\\.\\d*)?|\\.\\d+)([eE][+-]?\\d+)?`` (the forms urdfdom reads exactly as
  written) that is finite as a double.  Surrounding whitespace is refused too: urdfdom
  reads a trailing blank in ``mass``/``inertia`` as "not a float" and silently zeroes
  the inertial.
* a vector (``origin@xyz``, ``color@rgba``, ...): its numbers split on spaces, the only
  separator urdfdom knows (leading, trailing and repeated spaces allowed); a tab or line
  break inside the value (which an XML parser would otherwise report as a space) is
  refused, because urdfdom then fails to read the vector, and for an inertial
  ``<origin>`` that drops the inertial without failing.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from typing import NoReturn

from pendverify.display import shortened

#: A plain decimal literal; it must match the whole attribute (no surrounding whitespace).
DECIMAL = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")
NOT_A_NUMBER = "not a finite decimal number"
#: characters of a value quoted in a message (a longer one is shortened around "…")
QUOTE_WIDTH = 60
#: Whitespace an XML parser would normalise to a space inside an attribute, with its character reference.
RAW_WHITESPACE = {"\t": "&#9;", "\n": "&#10;", "\r": "&#13;"}


def quoted(value: object) -> str:
    """A value from the file as a message quotes it: its repr, the text shortened to ``QUOTE_WIDTH``."""
    return repr(shortened(value, QUOTE_WIDTH)) if isinstance(value, str) else repr(value)


def parse_number(raw: str) -> float | None:
    """The value of a plain decimal literal, or None if ``raw`` is not one or is not finite."""
    if not DECIMAL.fullmatch(raw):
        return None
    value = float(raw)
    return value if math.isfinite(value) else None


def why_not(raw: str) -> str:
    """Why ``raw`` is not a number, as a clause to append to the message ("" when no more is known)."""
    if raw != raw.strip() and DECIMAL.fullmatch(raw.strip()):
        return " (surrounding whitespace is not allowed: urdfdom does not read a trailing blank)"
    if DECIMAL.fullmatch(raw):
        return " (it overflows a double)"
    return ""


def parse_vector(raw: str, count: int, fail: Callable[[str], NoReturn]) -> tuple[float, ...]:
    """``count`` numbers separated by spaces (leading/trailing/repeated spaces allowed, as in urdfdom)."""
    if any(c in raw for c in RAW_WHITESPACE):
        fail(
            f"{quoted(raw)}: separate the numbers with spaces only; urdfdom does not split on tabs or "
            "line breaks"
        )
    pieces = [p for p in raw.split(" ") if p]
    if len(pieces) != count:
        fail(f"{quoted(raw)}: needs exactly {count} numbers separated by spaces, found {len(pieces)}")
    return parse_pieces(raw, pieces, fail)


def parse_pieces(raw: str, pieces: list[str], fail: Callable[[str], NoReturn]) -> tuple[float, ...]:
    """Each piece of ``raw`` (already split and counted) as a number, or ``fail`` naming the first bad one."""
    numbers = []
    for i, piece in enumerate(pieces, 1):
        number = parse_number(piece)
        if number is None:
            fail(f"{quoted(raw)}: number {i}, {quoted(piece)}, is {NOT_A_NUMBER}{why_not(piece)}")
        numbers.append(number)
    return tuple(numbers)
