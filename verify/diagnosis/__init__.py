"""What is wrong in a failing model and how to fix it: the entries, the shape of the difference,
a confirmed repair, the inertial parameters the model implies, and the known convention traps.

Internal: nothing here is public (``__all__`` is empty); the public names are those of
``pendverify.__all__``, ``pendverify.analytic.__all__`` and ``pendverify.api`` (docs/reference/api.md).
"""

__all__: list[str] = []
