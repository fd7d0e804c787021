"""A sweep's task: one parameter set through the battery, a pure function of strings and numbers.

It runs anywhere — a local worker process or a Dask worker — and returns a plain dict
(name, values, error, battery items as dicts, the set's URDF), which the main process
writes as a bundle (``pendverify.certify.issue.write_sweep_certificates``).
"""

from __future__ import annotations

from pendverify.certify.battery import BatterySettings, run_battery
from pendverify.certify.model_source import ModelSource
from pendverify.errors import PendverifyError
from pendverify.progress import quiet
from pendverify.robot.rebind import Binding
from pendverify.robot.writer import urdf_for


def set_urdf(model_cls, params, name: str, base_urdf: str | None, base_values: dict | None) -> str:
    """A set's URDF: the project's for a built-in model, else the base URDF rewritten for the set."""
    if base_urdf is None:
        return urdf_for(params, name)
    base = model_cls.params_type.from_mapping(base_values, "<sweep base>")
    return Binding.of(base_urdf, base).rewrite(params)


def certify_task(
    model: ModelSource,
    name: str,
    values: dict,
    settings: dict,
    base_urdf: str | None = None,
    base_values: dict | None = None,
) -> dict:
    """One set through the battery; a pure function of strings and numbers, so it runs anywhere.

    It draws no progress bar: the sweep's own bar is the only one."""
    with quiet():
        return _certify(model, name, values, settings, base_urdf, base_values)


def _certify(model, name, values, settings, base_urdf, base_values) -> dict:
    try:
        cls = model.load()
        params = cls.params_type.from_mapping(values, f"<sweep set {name}>")
        urdf = set_urdf(cls, params, name, base_urdf, base_values)
    except PendverifyError as exc:
        return {"name": name, "values": values, "error": str(exc), "items": []}
    items = run_battery(cls, params, urdf, BatterySettings(**settings))
    return {
        "name": name,
        "values": values,
        "error": None,
        "items": [i.as_dict() for i in items],
        "urdf": urdf,
    }
