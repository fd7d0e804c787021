"""What is wrong in a failing model and how to fix it: the entries, the shape of the difference,
a confirmed repair, the inertial parameters the model implies, and the known convention traps.

Internal (``__all__`` is empty): docs/reference/api.md lists what is public.
"""

__all__: list[str] = []
