"""One JSON policy for everything pendverify writes, and one record of provenance.

JSON has no infinity or NaN (Python's ``json`` would write the non-standard
literals ``Infinity`` and ``NaN``).  A failing check can have an infinite error
(det M not positive), so every document goes through ``to_json``: non-finite
numbers are written as the strings ``"inf"``, ``"-inf"`` and ``"nan"``, numpy
scalars and arrays as plain numbers and lists, and ``allow_nan=False`` makes any
value that slips through an error rather than invalid JSON.
"""

from __future__ import annotations

import importlib.metadata
import json
import math
import platform
from typing import Any

import numpy as np
import pinocchio


def plain(value: Any) -> Any:
    """``value`` with numpy types made plain and non-finite floats made strings, recursively."""
    if isinstance(value, np.ndarray):
        return [plain(v) for v in value.tolist()]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    return value


def to_json(value: Any, canonical: bool = False) -> str:
    """Standard JSON: indented with a final newline, or canonical (sorted keys, no spaces) for digests."""
    if canonical:
        return json.dumps(
            plain(value), sort_keys=True, separators=(",", ":"), ensure_ascii=False, allow_nan=False
        )
    return json.dumps(plain(value), indent=2, ensure_ascii=False, allow_nan=False) + "\n"


def versions() -> dict[str, str]:
    """The versions that produced a result: pendverify, Pinocchio, numpy, Python."""
    return {
        "pendverify": importlib.metadata.version("pendverify"),
        "pinocchio": pinocchio.__version__,
        "numpy": np.__version__,
        "python": platform.python_version(),
    }
