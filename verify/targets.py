"""What to verify: pairs of a closed-form model and a URDF loaded in Pinocchio.

``select_targets`` is the one dispatcher: ``check`` (the command and ``pendverify.check``),
``certify`` (``pendverify.certify.issue.certification_input``), ``mutate``, the scenes'
Pinocchio side (``pendverify.simulation.dynamics``) and the review folder turn their arguments
(a model, a URDF or ``erd:NAME``, parameters, the erd flag) into targets through it, so the same
arguments verify the same targets and a mistake gets one sentence
(``tests/test_one_target_dispatcher.py`` looks for a second).  The targets are

* the default parameter sets against their committed URDFs (``urdf/``);
* example-robot-data's double-pendulum URDFs against the double-pendulum reference system's
  closed form with parameters read off the URDF itself (skipped, with a sentence, when
  example-robot-data is not installed);
* a user's URDF against a user's parameter set, or (double pendulum) against
  the parameters read off that URDF;
* a user's own model file (``--analytic``, ``pendverify.analytic.plugin``) against a URDF.

Built-in and plug-in models take one path: the URDF is loaded, the model class's
geometry reader (or declared map) gives the coordinate map (the two reference systems read it
off the geometry, a plug-in declares it), and ``model_target`` pairs the two.  A parameter set
with no URDF is checked against the URDF the project writes for it (``params_target``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib.resources import files
from pathlib import Path

from pendverify.analytic import MODELS, ClosedFormModel, ParameterSet
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.analytic.plugin import check_model_outputs, load_model_class, plugin_parameters
from pendverify.analytic.source_file import where
from pendverify.errors import ParameterError, PendverifyError, UnknownNameError
from pendverify.robot import erd
from pendverify.robot.description import LoadedDescription, description_stem, is_description_text
from pendverify.robot.geometry import DEFAULT_G
from pendverify.robot.system import PinocchioSystem
from pendverify.robot.writer import urdf_for

PARAMETER_MATCH_RTOL = 1e-9
#: How a library error asks for the parameter set: it may reach a user of the CLI or of the Python API.
PARAMS_HINT = "--params on the command line, params= in the Python API"
#: ``source`` of a parameter set given as a mapping of values.
INLINE = "<inline>"


@dataclass
class Target:
    """One closed-form model and the Pinocchio system it is verified against.

    ``label`` names it in the report (``model:name``, or ``erd:NAME``); ``source`` is where its
    URDF came from; ``notes`` are what choosing the pair noticed (parameters read off the URDF,
    a parameter set that differs from the URDF's).
    """

    label: str
    model: ClosedFormModel
    system: PinocchioSystem
    source: str
    notes: list[str] = field(default_factory=list)

    def __repr__(self) -> str:
        return f"<Target {self.label}: {self.model.name}, {self.model.nv} dof, URDF {self.system.source}>"


@dataclass
class Selection:
    """What ``select_targets`` chose: the targets, and what it left out (one sentence each)."""

    targets: list[Target]
    skipped: list[str] = field(default_factory=list)

    def extend(self, other: Selection) -> None:
        """Add another selection's targets and skipped sentences to this one."""
        self.targets += other.targets
        self.skipped += other.skipped


def committed_urdf(model: str) -> Path:
    """The URDF the project commits for a built-in model's default parameter set."""
    return Path(str(files("pendverify.urdf") / f"{model}.urdf"))


def _model_class(name: str):
    if name not in MODELS:
        raise UnknownNameError("model", name, tuple(MODELS))
    return MODELS[name]


def default_target(model_name: str) -> Target:
    _, _, params = load_parameter_file(default_parameter_file(model_name))
    path = committed_urdf(model_name)
    cls = _model_class(model_name)
    return Target(model_name, cls(params), PinocchioSystem.for_model(cls, path, params.g), str(path))


def erd_target(stem: str, path: Path) -> Target:
    """example-robot-data's URDF ``stem`` against the double pendulum's closed form, with the
    parameters read off the URDF; labelled ``erd:{stem}``."""
    cls = _model_class(erd.MODEL)
    system = PinocchioSystem.for_model(cls, path)
    return Target(f"{erd.PREFIX}{stem}", cls(system.geometry.params), system, str(path))


def erd_targets() -> list[Target]:
    """Every double-pendulum URDF example-robot-data ships (an error when it is not installed)."""
    return [erd_target(stem, path) for stem, path in erd.family_urdfs().items()]


def erd_selection() -> Selection:
    """example-robot-data's targets, or none and ``erd.SKIPPED`` when it is not installed."""
    if erd.installed() is None:
        return Selection([], [erd.SKIPPED])
    return Selection(erd_targets())


def parameter_differences(urdf_params: ParameterSet, given: ParameterSet) -> list[str]:
    """Name each parameter where the URDF and the parameter set disagree."""
    notes = []
    for key, value in given.as_dict().items():
        read = getattr(urdf_params, key)
        if key == "l2":  # drawing length only: not in the dynamics
            continue
        if abs(read - value) > PARAMETER_MATCH_RTOL * max(abs(read), abs(value)):
            rel = (read - value) / value if value else float("inf")
            notes.append(f"the URDF gives {key} = {read:.6g}, the parameter set {value:.6g} ({rel:+.3%})")
    return notes


def model_target(
    cls: type[ClosedFormModel], urdf: str | Path, params: ParameterSet | None, name: str | None = None
) -> Target:
    """A model class, a URDF and (unless the URDF fixes them) its parameters: built-in or plug-in.

    ``urdf`` is a description's file path (URDF, xacro, MJCF), the XML text itself or a description
    already read (a Pinocchio model's, ``pendverify.robot.pinocchio_model``).  The target
    is labelled ``{model}:{name}``; ``name`` defaults to the file's stem without its format's
    suffixes (``arm.urdf.xacro`` → ``arm``), or ``urdf-text`` for text.
    """
    system = target_system(cls, urdf, params)
    notes = []
    read = system.geometry.params
    if params is None and cls.default_params is not None:
        params = cls.default_params
        notes.append("parameters: the model file's PARAMS")
        if read is not None:
            notes += parameter_differences(read, params)
    elif params is None:
        if read is None and not is_builtin(cls):
            raise PendverifyError(
                f"{where(cls)}: give the parameter set ({PARAMS_HINT}): the model file gives no PARAMS"
            )
        if read is None:
            raise PendverifyError(
                f"{system.source}: give the parameter set ({PARAMS_HINT}): a {cls.name} URDF alone "
                "does not fix the closed form"
            )
        params = read if isinstance(read, cls.params_type) else cls.params_type(**read.as_dict())
        notes.append("parameters read off the URDF")
    elif read is not None:
        notes += parameter_differences(read, params)
    if not hasattr(params, "g"):
        notes.append(f"the parameter set has no g: Pinocchio's gravity is {DEFAULT_G} m/s²")
    try:
        model = cls(params)
    except Exception as exc:
        raise PendverifyError(f"{cls.name}: building the model failed: {type(exc).__name__}: {exc}") from None
    try:
        check_model_outputs(model)
    except ParameterError as exc:  # a value beyond double's range: name the file it came from
        if "parameters read off the URDF" not in notes:
            raise
        raise ParameterError(
            system.source, exc.key, exc.value, f"{exc.rule} (as read off the URDF)"
        ) from None
    if name is None:
        name = _description_name(urdf)
    return Target(f"{cls.name}:{name}", model, system, system.source, notes)


def _description_name(urdf) -> str:
    """A target's name from its description: the file's stem, ``urdf-text``, or a Pinocchio model's name."""
    if isinstance(urdf, LoadedDescription):
        return urdf.model.name or "pinocchio-model"
    return "urdf-text" if is_description_text(urdf) else description_stem(urdf)


def params_target(
    params: ParameterSet,
    name: str = "inline",
    origin: str | None = None,
    model_cls: type[ClosedFormModel] | None = None,
) -> Target:
    """A parameter set against the URDF the project writes for it (``pendverify.robot.writer``).

    The model is ``model_cls``, by default the built-in model of the set (``params.model``).
    The target is labelled ``{model}:{name}`` (the CLI passes the parameter file's stem);
    ``origin`` says where the set came from in the URDF's source, ``<URDF of {origin}>``
    (default: the inline parameters).
    """
    cls = model_cls or _model_class(params.model)
    origin = origin or f"the inline {cls.name} parameters"
    model = cls(params)
    try:
        check_model_outputs(model)
    except ParameterError as exc:  # a value beyond double's range: name the file it came from
        raise ParameterError(origin, f"parameters.{exc.key}", exc.value, exc.rule) from None
    system = target_system(cls, None, params, origin)
    return Target(f"{cls.name}:{name}", model, system, system.source)


def target_system(
    cls: type[ClosedFormModel], urdf, params: ParameterSet | None, origin: str | None = None
) -> PinocchioSystem:
    """Pinocchio's side of a target: ``urdf`` (as ``model_target`` takes it) seen in ``cls``'s
    coordinates at the set's g, or, with no URDF, the URDF the project writes for the set
    (``pendverify.robot.writer``), its source ``<URDF of {origin}>``.  A scene's engines take
    theirs here too (``pendverify.simulation.dynamics``): the model itself is not evaluated."""
    g = getattr(params, "g", None)
    if urdf is not None:
        return PinocchioSystem.for_model(cls, urdf, g)
    return PinocchioSystem.for_model(cls, urdf_for(params), g, f"<URDF of {origin}>")


def is_builtin(cls: type[ClosedFormModel]) -> bool:
    """Whether ``cls`` is one of the built-in models (``pendverify.analytic.MODELS``)."""
    return MODELS.get(getattr(cls, "name", None)) is cls


def parameter_values(cls: type[ClosedFormModel], source) -> ParameterSet:
    """A parameter set of model class ``cls`` from a parameter file (TOML, whose ``model`` must be
    ``cls.name``), a flat mapping of the values (``{"m1": 1.0, ...}``) or a set of its
    ``params_type`` (returned as is).  Every value is checked against its quantity's rule."""
    if isinstance(source, ParameterSet):
        if not isinstance(source, cls.params_type):
            raise PendverifyError(
                f"{cls.name} needs {cls.params_type.__name__} parameters, got {type(source).__name__}; "
                "pass a parameter file or a mapping of values (params.as_dict())"
            )
        return source
    if isinstance(source, Mapping):
        return cls.params_type.from_mapping(dict(source), INLINE)
    if isinstance(source, (str, Path)):
        if not is_builtin(cls):
            return plugin_parameters(cls, where(cls), str(source))
        file_model, _, params = load_parameter_file(str(source))
        if file_model != cls.name:
            raise ParameterError(
                str(source), "model", file_model, f"must be {cls.name!r}, the model named with it"
            )
        return params
    raise PendverifyError(
        f"parameters are a TOML file, a mapping of values or a {cls.params_type.__name__}; "
        f"got a {type(source).__name__}"
    )


def _parameters_model(source) -> type[ClosedFormModel]:
    """The built-in model that parameters given without a model belong to."""
    if isinstance(source, (str, Path)):
        return _model_class(load_parameter_file(str(source))[0])
    if isinstance(source, ParameterSet) and source.model in MODELS:
        return _model_class(source.model)
    raise PendverifyError(
        "name the model of these parameters (--model on the command line, model= in the Python API)"
    )


def urdf_needed(model_cls: type[ClosedFormModel], why: str = "") -> PendverifyError:
    """The error of a model file or class given without the URDF to compare it with (``why``: in brackets)."""
    return PendverifyError(
        f"{where(model_cls)}: give --urdf (urdf= in the Python API): the URDF to verify {model_cls.name} "
        f"against{f' ({why})' if why else ''}"
    )


def select_targets(
    model_cls: type[ClosedFormModel] | None = None,
    urdf: str | Path | None = None,
    params=None,
    *,
    erd_urdfs: bool = True,
    origin: str | None = None,
) -> Selection:
    """The targets ``pendverify check`` and ``pendverify.check`` verify, from their arguments.

    ``model_cls`` is a model class (built-in, a model file's or the caller's), or None: every
    built-in model, or the one a parameter file names.  ``urdf`` is a description's path, its
    XML text, or ``erd:NAME`` (example-robot-data's URDF NAME).  ``params`` is a parameter file,
    a flat mapping of values or a parameter set (``parameter_values``).  ``erd_urdfs`` adds
    example-robot-data's double-pendulum URDFs wherever the double pendulum's default set is
    checked (``--no-erd``, ``erd=False`` turn it off); when example-robot-data is not installed
    they are skipped and ``Selection.skipped`` says so.

    * no URDF, no parameters: each built-in model named (all by default) with its default set
      against its committed URDF, and example-robot-data's URDFs as above;
    * ``erd:NAME`` without parameters, with the double pendulum (named or not): the target the
      default check labels ``erd:NAME``;
    * a URDF (or ``erd:NAME`` with another model or with parameters): the model against it, with
      the parameters given, or read off the URDF;
    * parameters without a URDF: a built-in model's set against the URDF the project writes for it,
      labelled by the parameter file's stem; ``origin`` names where a set given as values came
      from (a scene), as a file's path does (default: the inline parameters).

    A model file or class needs a URDF; bad input raises ``PendverifyError``.
    """
    name = None
    if erd.is_erd_spec(urdf):
        stem, path = erd.erd_urdf(urdf)
        if model_cls is None and params is None:
            model_cls = _model_class(erd.MODEL)
        if params is None and model_cls is MODELS[erd.MODEL]:
            return Selection([erd_target(stem, path)])
        urdf, name = path, f"erd_{stem}"
    if urdf is None and model_cls is not None and not is_builtin(model_cls):
        raise urdf_needed(model_cls)
    values = None
    if params is not None:
        model_cls = model_cls or _parameters_model(params)
        values = parameter_values(model_cls, params)
    if urdf is not None:
        if model_cls is None:
            raise PendverifyError(
                "with a URDF, name the model (--model or --analytic on the command line, the model "
                f"argument in the Python API) or give the parameter set ({PARAMS_HINT})"
            )
        try:
            return Selection([model_target(model_cls, urdf, values, name)])
        except ParameterError as exc:  # a value of the parameter file beyond double's range: name the file
            if not isinstance(params, (str, Path)) or not exc.source.startswith("<"):
                raise
            raise ParameterError(str(params), f"parameters.{exc.key}", exc.value, exc.rule) from None
    if values is not None:
        if isinstance(params, (str, Path)):
            origin = str(params)
        if origin is not None:
            return Selection([params_target(values, Path(origin).stem, origin, model_cls)])
        return Selection([params_target(values, model_cls=model_cls)])
    names = [model_cls.name] if model_cls is not None else list(MODELS)
    selection = Selection([default_target(n) for n in names])
    if erd_urdfs and erd.MODEL in names:
        selection.extend(erd_selection())
    return selection


def plugin_target(model_file: str, urdf: str | None, params=None) -> Target:
    """The target of a model file, its URDF and (optionally) its parameters, as ``check --analytic``
    (a parameter file, a mapping of values or a parameter set: ``parameter_values``)."""
    return select_targets(load_model_class(model_file), urdf, params, erd_urdfs=False).targets[0]
