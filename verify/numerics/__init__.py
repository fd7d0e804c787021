"""Compiled and high-precision back ends: the fast path, fixed-step methods, Taylor references.

Internal (``__all__`` is empty): docs/reference/api.md lists what is public.
"""

__all__: list[str] = []
