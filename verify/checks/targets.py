"""What to verify: pairs of a closed-form model and a URDF loaded in Pinocchio.

* the default parameter sets against their committed URDFs (``urdf/``);
* example-robot-data's double-pendulum URDFs against the double-pendulum reference system's closed form
  with parameters read off the URDF itself;
* a user's URDF against a user's parameter set, or (double pendulum) against
  the parameters read off that URDF;
* a user's own model file (``--analytic``, ``pendverify.analytic.plugin``) against a URDF.

Built-in and plug-in models take one path: the URDF is loaded, the model class's
geometry reader (or declared map) gives the coordinate map (the two reference systems read it off the
geometry, a plug-in declares it), and ``model_target`` pairs the two.  A parameter set
with no URDF is checked against the URDF the project writes for it (``params_target``).
``user_target`` and ``plugin_target`` read the CLI's options into these; the Python API
(``pendverify.api``) calls ``default_target``, ``params_target`` and ``model_target``
directly.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from importlib.resources import files
from pathlib import Path

from pendverify.analytic import MODELS, ClosedFormModel, ParameterSet
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.analytic.plugin import check_model_outputs, load_model_class, plugin_parameters
from pendverify.errors import PendverifyError, UnknownNameError
from pendverify.robot.description import description_stem, is_description_text
from pendverify.robot.erd import MODEL as ERD_MODEL
from pendverify.robot.erd import double_pendulum_urdfs
from pendverify.robot.seed_geometry import DEFAULT_G
from pendverify.robot.system import PinocchioSystem
from pendverify.robot.writer import urdf_for

PARAMETER_MATCH_RTOL = 1e-9
#: How a library error asks for the parameter set: it may reach a user of the CLI or of the Python API.
PARAMS_HINT = "--params on the command line, params= in the Python API"


@dataclass
class Target:
    label: str
    model: ClosedFormModel
    system: PinocchioSystem
    source: str
    notes: list[str] = field(default_factory=list)


def committed_urdf(model: str) -> Path:
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


def erd_targets() -> list[Target]:
    targets = []
    cls = _model_class(ERD_MODEL)
    for stem, path in double_pendulum_urdfs().items():
        system = PinocchioSystem.for_model(cls, path)
        model = cls(system.geometry.params)
        targets.append(Target(f"erd:{stem}", model, system, str(path)))
    return targets


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

    ``urdf`` is a description's file path (URDF, xacro, MJCF) or the XML text itself.  The target
    is labelled ``{model}:{name}``; ``name`` defaults to the file's stem without its format's
    suffixes (``arm.urdf.xacro`` → ``arm``), or ``urdf-text`` for text.
    """
    g = getattr(params, "g", None)
    system = PinocchioSystem.for_model(cls, urdf, g)
    notes = []
    read = system.geometry.params
    if params is None:
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
    check_model_outputs(model)
    if name is None:
        name = "urdf-text" if is_description_text(urdf) else description_stem(urdf)
    return Target(f"{cls.name}:{name}", model, system, system.source, notes)


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
    system = PinocchioSystem.for_model(cls, urdf_for(params), params.g, f"<URDF of {origin}>")
    return Target(f"{cls.name}:{name}", cls(params), system, system.source)


def user_target(model_name: str | None, urdf: str | None, params_file: str | None) -> Target:
    """A target from the CLI's --model / --urdf / --params."""
    params = None
    if params_file:
        file_model, _, params = load_parameter_file(params_file)
        if model_name and model_name != file_model:
            raise PendverifyError(f"{params_file}: model is {file_model!r}, but --model says {model_name!r}")
        model_name = file_model
    if model_name is None:
        raise PendverifyError("name the model with --model, or give --params")
    if urdf is None:  # the URDF of this parameter set, as the project writes it
        return params_target(params, Path(params_file).stem, params_file)
    return model_target(_model_class(model_name), urdf, params)


def plugin_target(model_file: str, urdf: str | None, params_file: str | None) -> Target:
    """A target from the CLI's --analytic / --urdf / --params."""
    cls = load_model_class(model_file)
    if urdf is None:
        raise PendverifyError(f"{model_file}: give --urdf: the URDF to verify {cls.name} against")
    params = plugin_parameters(cls, model_file, params_file) if params_file else None
    return model_target(cls, urdf, params)
