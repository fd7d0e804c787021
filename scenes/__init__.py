"""Data shipped with pendverify: the scenes folder (read with importlib.resources).

Nothing here is public API (``__all__`` is empty).
"""

__all__: list[str] = []
