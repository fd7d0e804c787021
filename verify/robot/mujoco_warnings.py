"""MuJoCo's warnings, caught: no ``MUJOCO_LOG.TXT`` in the user's folder, no line of MuJoCo's own.

MuJoCo's default warning handler prints ``WARNING: ...`` and appends the message, dated, to
``MUJOCO_LOG.TXT`` in the current working folder: the user's folder, whatever output they named.
``caught()`` installs a handler (``mujoco.set_mju_user_warning``) that collects the messages
instead while a block runs, and puts back the handler that was there (none: MuJoCo's default)
when it ends.  The caller says what the messages mean: ``build_mjcf_model`` turns each into a
note on the description.  MuJoCo's errors need no handler: its Python bindings raise them
(a compile error is a ``ValueError``), and they write no log.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import mujoco


@contextmanager
def caught() -> Iterator[list[str]]:
    """The warnings MuJoCo gives while the block runs, in order, each once."""
    messages: list[str] = []

    def collect(message: str) -> None:
        if message not in messages:
            messages.append(message)

    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(collect)
    try:
        yield messages
    finally:
        mujoco.set_mju_user_warning(previous)
