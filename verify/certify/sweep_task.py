"""A sweep's task: a chunk of parameter sets through the battery, a pure function of strings and numbers.

It runs anywhere — a local worker process or a Dask worker — and returns one ``SetResult``
per set (name, values, the battery's items and notes as it made them, the set's URDF),
which the main process writes as a bundle (``pendverify.certify.issue.write_sweep_certificates``).

A chunk of k sets is one task, so the per-task costs (submitting, pickling, a Dask
round trip) are paid once per k sets.  What a worker loads is kept for the sets of
every chunk it runs, in the worker process: the model class (``ModelSource.load``, once
per process), its generated module (``pendverify.numerics.codegen.cache``: from disk,
compiled code from numba's cache) and the base URDF's parameter binding of a model file
(``_binding``).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

from pendverify.certify.battery import BatteryRun, BatterySettings, run_battery
from pendverify.certify.model_source import ModelSource
from pendverify.checks.evidence import Evidence
from pendverify.errors import PendverifyError
from pendverify.progress import quiet
from pendverify.robot.rebind import Binding
from pendverify.robot.writer import urdf_for


def set_urdf(model_cls, params, name: str, base_urdf: str | None, base_values: dict | None) -> str:
    """A set's URDF: the project's for a built-in model, else the base URDF rewritten for the set."""
    if base_urdf is None:
        return urdf_for(params, name)
    return _binding(model_cls, base_urdf, tuple(base_values.items())).rewrite(params)


@functools.lru_cache(maxsize=4)
def _binding(model_cls, base_urdf: str, base_items: tuple) -> Binding:
    """The base URDF's binding to the base set, parsed once per worker process (URDF text and values)."""
    base = model_cls.params_type.from_mapping(dict(base_items), "<sweep base>")
    return Binding.of(base_urdf, base)


@dataclass(frozen=True)
class SetResult:
    """One set of a sweep through the battery: its name and values, and either ``battery`` (the
    items and notes, as ``run_battery`` made them) with the set's ``urdf``, or ``error``: why the
    set could not be made (its values refused, its URDF not rewritten)."""

    name: str
    values: dict
    battery: BatteryRun | None = None
    urdf: str = ""
    error: str | None = None

    @property
    def items(self) -> list[Evidence]:
        return self.battery.items if self.battery is not None else []

    @property
    def passed(self) -> bool:
        """Whether the set was made and every battery item passed: its certificate is written."""
        return self.battery is not None and self.battery.passed


def certify_chunk(
    model: ModelSource,
    sets: list[tuple[str, dict]],
    settings: dict,
    base_urdf: str | None = None,
    base_values: dict | None = None,
) -> list[SetResult]:
    """Each (name, values) of ``sets`` through the battery, in order: one result per set.

    It draws no progress bar: the sweep's own bar is the only one."""
    with quiet():
        return [_certify(model, name, values, settings, base_urdf, base_values) for name, values in sets]


def _certify(model, name, values, settings, base_urdf, base_values) -> SetResult:
    try:
        cls = model.load()
        params = cls.params_type.from_mapping(values, f"<sweep set {name}>")
        urdf = set_urdf(cls, params, name, base_urdf, base_values)
    except PendverifyError as exc:
        return SetResult(name, values, error=str(exc))
    return SetResult(name, values, run_battery(cls, params, urdf, BatterySettings(**settings)), urdf)
