"""Progress bars: one at a time, on a terminal only.

``bar(total, desc, unit)`` is a tqdm bar on stderr when stderr is a terminal and
no other bar is open in this process; inside it (and inside ``quiet()``, which a
sweep's worker task uses) every further bar is disabled, so a long run shows one
bar, never bars drawn over each other.  Tests and pipes see none.
"""

from __future__ import annotations

import sys
import threading
from contextlib import contextmanager

_lock = threading.Lock()
_silenced = 0  # open bars and quiet() blocks in this process


def shown() -> bool:
    """Whether a new bar would be drawn: stderr is a terminal and nothing silences bars."""
    return _silenced == 0 and sys.stderr.isatty()


def new_bar(total: int, desc: str, unit: str = "it", leave: bool = True, initial: int = 0):
    """A tqdm bar, disabled unless ``shown()``; the caller closes it (nested bars use this)."""
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, unit=unit, leave=leave, initial=initial, disable=not shown())


@contextmanager
def quiet():
    """No bar is drawn inside this block (a worker's task; the steps of an outer bar)."""
    global _silenced
    with _lock:
        _silenced += 1
    try:
        yield
    finally:
        with _lock:
            _silenced -= 1


@contextmanager
def bar(total: int, desc: str, unit: str = "it", initial: int = 0):
    """The one bar of a long run; every bar opened inside it stays hidden."""
    b = new_bar(total, desc, unit, initial=initial)
    try:
        with quiet():
            yield b
    finally:
        b.close()
