"""The certification battery, certificates and sweeps.

Internal: nothing here is public (``__all__`` is empty); the public names are those of
``pendverify.__all__``, ``pendverify.analytic.__all__`` and ``pendverify.api`` (docs/reference/api.md).
"""

__all__: list[str] = []
