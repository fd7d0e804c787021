"""The URDF of a parameter set whose model ships a writer (the reference systems'; the writers
and their frames are ``pendverify.analytic.reference_urdfs``): any other model is given with its URDF."""

from __future__ import annotations

from pendverify.analytic import ParameterSet
from pendverify.analytic.reference_urdfs import WRITERS
from pendverify.errors import PendverifyError


def urdf_for(params: ParameterSet, name: str | None = None) -> str:
    """The URDF text of a parameter set whose model has a writer (the reference systems); robot ``name``."""
    model = getattr(params, "model", type(params).__name__)
    if model not in WRITERS:
        raise PendverifyError(f"no URDF writer for model {model!r}: give the URDF that describes it")
    return WRITERS[model](params, name or model)
