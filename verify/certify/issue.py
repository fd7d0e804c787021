"""Issuing and rechecking certificates: what ``pendverify certify`` and ``recheck`` call.

``certification_input`` turns the ways a user names a set — a parameter file; a
URDF (a path or ``erd:NAME``) with a parameter file, or with a model whose
parameters are read off the URDF; a model file (``--analytic``) with its URDF and
parameter file — into (bundle name, model, parameters, URDF text).  ``issue``
refuses an existing bundle before any work, runs the battery on that URDF, and
writes the bundle only if every item passes.  ``recheck``
verifies a certificate's digest and re-runs its battery.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from pendverify.analytic import ParameterSet
from pendverify.analytic.params import load_parameter_file
from pendverify.analytic.plugin import plugin_parameters
from pendverify.certify.battery import BatteryItem, BatterySettings, run_battery
from pendverify.certify.certificate import (
    build_certificate,
    compare_items,
    refuse_existing,
    verify_digest,
    write_bundle,
)
from pendverify.certify.model_source import ModelSource
from pendverify.checks.targets import PARAMS_HINT
from pendverify.errors import CertificateError, ParameterError, PendverifyError
from pendverify.robot.erd import resolve_urdf
from pendverify.robot.system import PinocchioSystem
from pendverify.robot.writer import urdf_for


@dataclass(frozen=True)
class CertificationInput:
    name: str
    model: ModelSource
    params: ParameterSet
    urdf: str


def certification_input(
    params_file: str | None = None,
    urdf: str | None = None,
    model: str | None = None,
    urdf_params: str | None = None,
    analytic: str | None = None,
) -> CertificationInput:
    """The set to certify, from a parameter file, a URDF with a parameter file or a model name,
    or a model file (``analytic``; a ``model`` ending in .py counts as one) with a URDF and parameters."""
    if analytic is None and model is not None and str(model).endswith(".py"):
        analytic, model = model, None
    if analytic is not None:
        if model is not None:
            raise PendverifyError(f"{analytic}: give a model file or a built-in model name, not both")
        return _plugin_input(analytic, urdf, urdf_params or params_file)
    if urdf:
        path, name = resolve_urdf(urdf)
        text = path.read_text()
        if urdf_params:
            model_name, _, params = load_parameter_file(urdf_params)
            if model and model != model_name:
                raise ParameterError(
                    urdf_params, "model", model_name, f"must be {model!r}, the model named with it"
                )
            return CertificationInput(name, ModelSource.of_builtin(model_name), params, text)
        if not model:
            raise PendverifyError(f"with a URDF, name the model or give the parameter set ({PARAMS_HINT})")
        params = PinocchioSystem.from_urdf(model, text, source=str(path)).geometry.params
        if params is None:
            raise PendverifyError(
                f"{path}: give the parameter set ({PARAMS_HINT}): "
                f"a {model} URDF alone does not fix the closed form"
            )
        return CertificationInput(name, ModelSource.of_builtin(model), params, text)
    if params_file:
        model_name, name, params = load_parameter_file(params_file)
        return CertificationInput(name, ModelSource.of_builtin(model_name), params, urdf_for(params, name))
    raise PendverifyError("give a parameter file, a URDF, a model file (--analytic), or a sweep")


def _plugin_input(model_file: str, urdf: str | None, params_file: str | None) -> CertificationInput:
    """A model file, its URDF and its parameter file (as ``check --analytic``)."""
    source = ModelSource.of_file(model_file)
    cls = source.load()
    if urdf is None:
        raise PendverifyError(f"{model_file}: give the URDF to certify {cls.name} against (--urdf, urdf=)")
    if params_file is None:
        raise PendverifyError(
            f"{model_file}: give the parameter set ({PARAMS_HINT}): a model file has no parameters of its own"
        )
    params = plugin_parameters(cls, model_file, params_file)
    if not hasattr(params, "g"):
        raise ParameterError(
            params_file,
            "parameters.g",
            None,
            "certify needs a gravity parameter g: its runs set gravity by it",
        )
    path, name = resolve_urdf(urdf)
    return CertificationInput(name, source, params, path.read_text())


@dataclass(frozen=True)
class Issued:
    items: list[BatteryItem]
    certificate: dict | None = None
    path: Path | None = None

    @property
    def certified(self) -> bool:
        return self.certificate is not None


def issue(target: CertificationInput, settings: BatterySettings, output, force: bool = False) -> Issued:
    """Run the battery on the target's URDF; write the bundle only if every item passes."""
    refuse_existing(output, target.name, force)
    cls = target.model.load()
    items = run_battery(cls, target.params, target.urdf, settings)
    if not all(i.passed for i in items):
        return Issued(items)
    notes = PinocchioSystem.for_model(cls, target.urdf, target.params.g).notes
    cert = build_certificate(
        target.name, target.model, target.params, target.urdf, settings, items, notes=notes
    )
    path = write_bundle(output, target.name, target.params, target.urdf, cert, force, target.model)
    return Issued(items, cert, path)


def write_sweep_certificates(sweep, results, output, force: bool = False) -> int:
    """Write the bundle of every set of a finished sweep whose battery passed; return how many."""
    written = 0
    params_type = sweep.model.load().params_type
    for r in results:
        if r["error"] is None and all(i["passed"] for i in r["items"]):
            params = params_type.from_mapping(r["values"])
            items = [BatteryItem(**i) for i in r["items"]]
            settings = BatterySettings(**sweep.settings.as_dict())
            cert = build_certificate(r["name"], sweep.model, params, r["urdf"], settings, items)
            write_bundle(output, r["name"], params, r["urdf"], cert, force, sweep.model)
            written += 1
    return written


@dataclass(frozen=True)
class Rechecked:
    certificate: dict
    items: list[BatteryItem]
    differences: list[str]

    @property
    def passed(self) -> bool:
        return not self.differences and all(i.passed for i in self.items)


def recheck(path: str) -> Rechecked:
    """Verify a certificate's digest (a CertificateError if it fails), then re-run its battery."""
    try:
        with open(path, encoding="utf-8") as fh:
            cert = json.load(fh)
    except FileNotFoundError:
        raise CertificateError(f"{path}: file not found") from None
    except json.JSONDecodeError as exc:
        raise CertificateError(f"{path}: not JSON: {exc}") from None
    verify_digest(cert, path)
    cls = ModelSource.from_certificate(cert, path).load()  # a plug-in: from the embedded source
    params = cls.params_type.from_mapping(cert["parameters"], path, "parameters.")
    items = run_battery(cls, params, cert["urdf"]["text"], BatterySettings(**cert["settings"]))
    return Rechecked(cert, items, compare_items(cert["checks"], items))
