"""URDFs in Pinocchio: strict reading, coordinate maps, a model's geometry reader, a set's URDF.

Internal (``__all__`` is empty): docs/reference/api.md lists what is public.
"""

__all__: list[str] = []
