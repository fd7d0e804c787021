"""Benchmarks: work-precision diagrams and timing, figures as ratios measured in the same run.

Internal (``__all__`` is empty): docs/reference/api.md lists what is public.
"""

__all__: list[str] = []
