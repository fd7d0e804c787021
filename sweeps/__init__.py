"""Data shipped with pendverify: the sweeps folder (read with importlib.resources).

Nothing here is public API (``__all__`` is empty).
"""

__all__: list[str] = []
