"""URDFs in Pinocchio: strict reading, coordinate maps, the reference systems' geometry, the writer.

Internal (``__all__`` is empty): docs/reference/api.md lists what is public.
"""

__all__: list[str] = []
