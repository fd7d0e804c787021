"""The checks: states, tolerances, the trust rule, verdicts, diagnoses and the report.

Internal (``__all__`` is empty): docs/reference/api.md lists what is public.
"""

__all__: list[str] = []
