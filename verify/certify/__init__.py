"""The certification battery, certificates and sweeps.

Internal (``__all__`` is empty): docs/reference/api.md lists what is public.
"""

__all__: list[str] = []
