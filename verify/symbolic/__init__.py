"""SymPy's view of a model: Lagrange's equations, the exact comparison, mutation testing.

Internal (``__all__`` is empty): docs/reference/api.md lists what is public.
"""

__all__: list[str] = []
