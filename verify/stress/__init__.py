"""Hard cases that must stay numerically stable, or be refused.

Internal (``__all__`` is empty): docs/reference/api.md lists what is public.
"""

__all__: list[str] = []
