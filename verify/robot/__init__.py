"""URDFs in Pinocchio: strict reading, coordinate maps, the geometry readers' registry, a set's URDF.

Internal (``__all__`` is empty): docs/reference/api.md lists what is public.
"""

__all__: list[str] = []
