"""Issuing and rechecking certificates: what ``pendverify certify`` and ``recheck`` call.

``certification_input`` turns the ways a user names a set — a parameter file; a
URDF (a path or ``erd:NAME``) with a parameter file, or with a model whose
parameters are read off the URDF; a model file (``--analytic``) with its URDF and
parameter file — into (bundle name, model, parameters, URDF text).  ``issue``
refuses an existing bundle before any work, runs the battery on that URDF, and
writes the bundle only if every item passes (signed when given a key).  ``recheck``
checks a certificate's schema, digest and, with ``trust``, its signature before it
loads the model (embedded Python only when trusted), then its derived fields, and
re-runs its battery, each invariant item on the engine it records.

Every name that becomes a file name is checked where it is read
(``pendverify.certify.names``): a parameter file's ``name``, a URDF's stem, a sweep's
set names.  A set certified on a URDF is named after its model, then the URDF
(``names.set_name``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from pendverify.analytic import ParameterSet
from pendverify.analytic.params import load_parameter_file
from pendverify.certify.battery import BatteryRun, BatterySettings, run_battery
from pendverify.certify.battery_item import items_html
from pendverify.certify.bundle import check_files_beside, refuse_existing, verify_signature, write_bundle
from pendverify.certify.certificate import build_certificate, compare_items, derived_constants, verify_digest
from pendverify.certify.model_source import ModelSource
from pendverify.certify.names import check_name, set_name
from pendverify.certify.reading import read_certificate
from pendverify.certify.schema import check_derived, check_schema
from pendverify.certify.signing import fingerprint
from pendverify.certify.simulations import recorded_engines
from pendverify.certify.sweep_task import SetResult
from pendverify.checks.evidence import Evidence
from pendverify.display import REPR_LIMIT, html_lines, listed, shortened
from pendverify.errors import CertificateError, ParameterError, PendverifyError
from pendverify.robot.description import LoadedDescription
from pendverify.robot.erd import resolve_urdf
from pendverify.robot.pinocchio_model import certified_text
from pendverify.robot.writer import urdf_for
from pendverify.targets import select_targets


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
    or a model file (``analytic``; a ``model`` ending in .py counts as one) with a URDF and parameters.

    The target is chosen as ``check`` chooses it (``pendverify.targets.select_targets``, the
    same errors); what certify adds is the bundle's name, checked where it is read, the URDF
    text the certificate embeds, and a gravity parameter."""
    if analytic is None and model is not None and str(model).endswith((".py", ".toml")):
        analytic, model = model, None
    if analytic is not None and model is not None:
        raise PendverifyError(f"{analytic}: give a model file or a built-in model name, not both")
    source = None if analytic is None else ModelSource.of_file(analytic)
    if source is None and not urdf and not params_file:
        raise PendverifyError("give a parameter file, a URDF, a model file (--analytic), or a sweep")
    if source is not None:
        model_cls, params, urdf = source.load(), urdf_params or params_file, urdf or None
    elif urdf:
        model_cls, params = (None if not model else ModelSource.of_builtin(model).load()), urdf_params
    else:
        model_cls, params = None, params_file
    where, name, description, text = None, None, None, None
    if urdf is not None:
        where, name, description, text = _urdf_input(urdf)
    (target,) = select_targets(model_cls, description, params, erd_urdfs=False).targets
    cls, values = type(target.model), target.model.params
    if source is None:
        source = ModelSource.of_builtin(cls.name)
    elif not hasattr(values, "g"):
        raise ParameterError(
            params or analytic,
            "parameters.g",
            None,
            "certify needs a gravity parameter g: its runs set gravity by it",
        )
    if urdf is None:
        _, name, _ = load_parameter_file(params_file)
        check_name(name, str(params_file), "name")
        return CertificationInput(name, source, values, urdf_for(values, name))
    text = text if text is not None else target.system.urdf.text  # a xacro file's: the URDF it expands to
    return CertificationInput(set_name(cls.name, name, where), source, values, text)


def _urdf_input(urdf: str | LoadedDescription) -> tuple[str, str, str | LoadedDescription, str | None]:
    """(where it came from, bundle name, the description to read, its URDF text if known) of a URDF
    argument: a path, ``erd:NAME``, or a model given as a Pinocchio object (its name names the
    bundle; its text is ``certified_text``).  The name must be a valid bundle name."""
    if isinstance(urdf, LoadedDescription):
        name = urdf.model.name
        check_name(name, urdf.source, "model name (it names the bundle)")
        return urdf.source, name, urdf, certified_text(urdf)
    path, name = resolve_urdf(urdf)
    check_name(name, str(urdf), "URDF file name (its stem names the bundle)")
    return str(path), name, str(path), None


def check_sweep_names(sweep, source: str) -> None:
    """Every set name of a sweep is a valid bundle name (checked before any set runs)."""
    for name, _ in sweep.sets:
        check_name(name, source, "set name (the model's name and the set's index)")


@dataclass(frozen=True)
class Issued:
    """What ``issue`` (``pendverify.certify_set``) did: every battery item's evidence and, when all
    of them pass, the certificate written and its path; ``not_run``: why a part of the battery
    did not apply to the model (``BatteryRun.not_run``)."""

    items: list[Evidence]
    certificate: dict | None = None
    path: Path | None = None
    not_run: tuple[str, ...] = ()

    @property
    def certified(self) -> bool:
        """Whether every item passed and the certificate was written."""
        return self.certificate is not None

    def __repr__(self) -> str:
        failed = [i.name for i in self.items if not i.passed]
        if self.certified:
            return f"<Issued certified: {len(self.items)} items pass; {shortened(str(self.path), 200)}>"
        return f"<Issued not certified: {len(failed)} of {len(self.items)} items fail: {listed(failed, 200)}>"

    def _repr_html_(self) -> str:
        where = f": {self.path}" if self.certified else ": some items fail, no certificate written"
        return items_html(self.items, f"{'certified' if self.certified else 'not certified'}{where}")


def issue(
    target: CertificationInput,
    settings: BatterySettings,
    output,
    force: bool = False,
    key=None,
    exporter=None,
) -> Issued:
    """Run the battery on the target's URDF; write the bundle only if every item passes.

    ``key`` (an Ed25519 private key, ``signing.load_private_key``) signs the certificate;
    ``exporter`` (the certificate → the files of the model's code, verified: ``certify --export``)
    adds files to the bundle, which the signature covers."""
    check_name(target.name, "<certify>", "name")
    refuse_existing(output, target.name, force)
    battery = run_battery(target.model.load(), target.params, target.urdf, settings)
    if not battery.passed:
        return Issued(battery.items, not_run=battery.not_run)
    cert, path = write_certificate(
        target.name, target.model, target.params, target.urdf, settings, battery, output, force, key, exporter
    )
    return Issued(battery.items, cert, path, battery.not_run)


def write_certificate(
    name: str,
    model: ModelSource,
    params: ParameterSet,
    urdf: str,
    settings: BatterySettings,
    battery: BatteryRun,
    output,
    force: bool = False,
    key=None,
    exporter=None,
) -> tuple[dict, Path]:
    """Build the certificate of a set whose battery passed and write its bundle (signed by
    ``key`` if given): (the certificate, its path).

    The one way a certificate is made, for a set certified alone (``issue``) and for each
    set of a sweep (``write_sweep_certificates``): one set under one name, with its URDF
    and settings, gets the same certificate either way, items, figures and notes included.
    Only what is each run's own differs: ``date`` (the time of certification), ``digest``
    (which covers it) and, when signed, ``signature``'s key.  (A sweep names its sets
    itself, by the model's name and the set's index; a set certified alone is named by its
    parameter file, or by its model and URDF.)"""
    check_name(name, "<certify>", "name")
    keyid = fingerprint(key.public_key()) if key is not None else None
    cert = build_certificate(name, model, params, urdf, settings, battery, keyid=keyid)
    extra = exporter(cert) if exporter is not None else {}
    path = write_bundle(
        output,
        name,
        params,
        urdf,
        cert,
        force,
        model,
        key,
        description_format=battery.description_format,
        extra_files=extra,
    )
    return cert, path


def write_sweep_certificates(sweep, results: list[SetResult], output, force: bool = False, key=None) -> int:
    """Write the bundle of every set of a finished sweep whose battery passed (each signed by
    ``key`` if given); return how many."""
    written = 0
    params_type = sweep.model.load().params_type
    for r in results:
        if r.passed:
            params = params_type.from_mapping(r.values)
            write_certificate(
                r.name, sweep.model, params, r.urdf, sweep.settings, r.battery, output, force, key
            )
            written += 1
    return written


@dataclass(frozen=True)
class Rechecked:
    certificate: dict
    items: list[Evidence]
    differences: list[str]
    signature: str = ""  # what was established about the signature, in words

    @property
    def passed(self) -> bool:
        return not self.differences and all(i.passed for i in self.items)

    def __repr__(self) -> str:
        name = shortened(str(self.certificate.get("name", "?")), 60)
        failed = [i.name for i in self.items if not i.passed]
        head = f"<Rechecked {name}: {'passed' if self.passed else 'FAILED'}, {len(self.items)} items"
        tail = f", {len(failed)} fail ({listed(failed, 80)})" if failed else ""
        tail += f", {len(self.differences)} difference(s) from the certificate" if self.differences else ""
        return f"{head}{tail}; {shortened(self.signature, REPR_LIMIT - len(head) - len(tail) - 3)}>"

    def _repr_html_(self) -> str:
        name = self.certificate.get("name", "?")
        caption = f"recheck of {name}: {'passed' if self.passed else 'FAILED'}; {self.signature}"
        return items_html(self.items, caption) + html_lines(self.differences)


RUN_EMBEDDED_CODE = "--run-embedded-code"


def recheck(path: str, trust: str | None = None, run_embedded_code: bool = False) -> Rechecked:
    """Check a certificate, then re-run its battery.

    In this order, each failure a PendverifyError naming the field or the key: the file
    (bounded: ``pendverify.certify.reading``), the schema (the settings within
    certify's bounds), the digests, with ``trust`` (a public-key PEM) the signature
    and the bundle's files beside it — and only then the model.  A built-in or text
    model is data; an embedded Python model runs only when the trusted key signed the
    certificate, or when ``run_embedded_code`` says the caller trusts it anyway.
    """
    data, cert = read_certificate(path)
    check_schema(cert, path)
    verify_digest(cert, path)
    source = ModelSource.from_certificate(cert, path)
    check_files_beside(path, cert)
    if trust is not None:
        signature = verify_signature(path, cert, trust, data)
    elif "signature" in cert:
        signature = f"signed by key {cert['signature']['keyid']}: not verified (give --trust PUBLIC.pem)"
    else:
        signature = "unsigned: only the digest was checked (it detects accidental corruption, not edits)"
    if source.runs_code and trust is None and not run_embedded_code:
        raise CertificateError(
            f"{path}: refused: its model is embedded Python source ({shortened(source.file, 60)}), which "
            "recheck would run, and no trusted key vouches for it; give --trust PUBLIC.pem (the key "
            f"that signed it), or {RUN_EMBEDDED_CODE} if you trust the code itself"
        )
    cls = source.load()
    params = cls.params_type.from_mapping(cert["parameters"], path, "parameters.")
    check_derived(cert, derived_constants(source, params), path)
    settings = BatterySettings(**cert["settings"])
    engines = recorded_engines(cert["checks"])  # each invariant item on the engine it ran on
    items = run_battery(cls, params, cert["urdf"]["text"], settings, engines).items
    return Rechecked(cert, items, compare_items(cert["checks"], items), signature)
