"""Scenes: declared effects, right-hand sides, integrators and invariants.

Internal (``__all__`` is empty): docs/reference/api.md lists what is public.
"""

__all__: list[str] = []
