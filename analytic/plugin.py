"""Load a user's closed-form model from a Python file (``--analytic FILE``).

The file is imported by path as ``pendverify.plugins.<stem>`` (``module_name``: its stem
made a valid identifier, a second file of the same stem ``<stem>_2``; the same file
keeps its name).  It must define
exactly one concrete subclass of ``pendverify.analytic.ClosedFormModel``
(classes it merely imports do not count) with

* ``name`` (a non-empty string), equal to the ``model`` key of its parameter
  files and to ``params_type.model``;
* ``params_type``: a frozen dataclass subclassing ``ParameterSet`` whose fields
  are ``quantity(kind, doc)`` entries;
* ``coordinates`` and ``angular`` of equal length, ``inputs`` and ``disturbances``;
* every abstract method of the interface (M, C or C·q̇, H; ``input_matrix``
  too when it declares ``inputs``; V is optional), and the coordinate map
  (``urdf_joints``, ``joint_transform``, ``joint_offset``; see ``pendverify.robot.joint_map``).

A file without such a class may instead define ``METHOD`` (a ``sympy.physics.mechanics``
derivation, ``pendverify.analytic.mechanics_model``), ``DYNAMICS`` (a right-hand side
ẋ = f(x, u) in Python, ``pendverify.analytic.python_dynamics``) or the functions ``M(q, p)``,
``C(q, v, p)``, ``G(q, p)``, … (NumPy code, ``pendverify.analytic.numpy_model``), each with its
``DECLARATION``; which it is, is decided in that order.

``validate_model_class`` checks these rules on any class (the Python API applies it to a
class written in the caller's own code).  ``examples/cart_pole.py`` is a complete
plug-in.  The built-in models are plug-ins of the same kind: ``--analytic
analytic/double_pendulum.py`` loads the double-pendulum reference system through this
same path.  Every problem is a ``PendverifyError`` naming the file (and the line, for an
exception raised while importing it).
"""

from __future__ import annotations

import dataclasses
import importlib.util
import inspect
import sys
import traceback
from pathlib import Path

import numpy as np

from pendverify.analytic import ClosedFormModel, ParameterSet
from pendverify.analytic.forms import INTERFACE
from pendverify.analytic.module_names import module_name
from pendverify.analytic.numeric_values import first_non_finite, model_value, parameters_overflow
from pendverify.analytic.params import parse_parameter_document, read_parameter_toml
from pendverify.analytic.source_file import where
from pendverify.errors import (
    FileAccessError,
    ParameterError,
    PendverifyError,
    UserCodeError,
    folder_given,
    missing_file,
    wrong_kind,
)
from pendverify.file_kinds import KINDS, suffix_kind

#: the model files imported so far (resolved paths): an exception raised in one is the user's
_LOADED: set[str] = set()


def _described(exc: BaseException) -> str:
    if isinstance(exc, SystemExit):
        return f"SystemExit({exc.code!r}): a model file must not exit"
    return f"{type(exc).__name__}: {exc}"


def user_code_error(exc: BaseException) -> UserCodeError | None:
    """A UserCodeError naming the model file and line when ``exc`` was raised in a loaded model file.

    The innermost frame of the traceback that lies in a model file names the place;
    None when no frame does (the exception is pendverify's own).
    """
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if _resolved(f.filename) in _LOADED]
    if not frames:
        return None
    f = frames[-1]
    return UserCodeError(
        f"{f.filename}, line {f.lineno}", f"the model raised {_described(exc)} (in {f.name})"
    )


def _resolved(filename: str) -> str:
    try:
        return str(Path(filename).resolve())
    except (OSError, ValueError):  # pragma: no cover - a frame of a file that is gone
        return filename


def _import(path: Path):
    resolved = str(path.resolve())
    name = module_name(path)
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise PendverifyError(f"{path}: not a Python file that can be imported")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up while the file runs
    try:
        spec.loader.exec_module(module)
    except KeyboardInterrupt:
        del sys.modules[name]
        raise
    except OSError as exc:
        del sys.modules[name]
        raise FileAccessError(str(path), "read", exc.strerror or str(exc)) from None
    except BaseException as exc:  # SystemExit too: a model file that exits must not end the run
        del sys.modules[name]
        if isinstance(exc, SyntaxError) and exc.lineno:
            line, text = f", line {exc.lineno}", f"{type(exc).__name__}: {exc.msg}"
        else:
            frames = [f for f in traceback.extract_tb(exc.__traceback__) if _resolved(f.filename) == resolved]
            line, text = (f", line {frames[-1].lineno}" if frames else ""), _described(exc)
        raise UserCodeError(f"{path}{line}", f"importing it failed: {text}") from None
    _LOADED.add(resolved)
    return module


def validate_model_class(cls: type[ClosedFormModel], path: str | Path | None = None) -> None:
    """Check that ``cls`` is a usable closed-form model class, as a model file's class must be.

    The rules are the module docstring's: ``name``, a ``params_type`` dataclass of
    ``quantity()`` fields whose ``model`` is that name, ``coordinates`` and ``angular``,
    ``inputs`` and ``disturbances``, every abstract method, and ``input_matrix`` when it
    declares inputs.  ``path`` names the file in messages (default: the file defining
    ``cls``).  Raises ``PendverifyError`` naming the file, the class and the rule broken;
    returns None when ``cls`` passes.  ``load_model_class`` applies it to the class a
    model file defines; ``pendverify.api.load_model`` to a class given in Python.
    """
    path = Path(where(cls)) if path is None else Path(path)

    def fail(problem: str):
        raise PendverifyError(f"{path}: {cls.__name__}: {problem}")

    if inspect.isabstract(cls):
        fail(f"methods of the interface not implemented: {', '.join(sorted(cls.__abstractmethods__))}")
    name = getattr(cls, "name", None)
    if not isinstance(name, str) or not name:
        fail("needs a class attribute name = '<model name>'")
    params_type = getattr(cls, "params_type", None)
    if not (inspect.isclass(params_type) and issubclass(params_type, ParameterSet)):
        fail("params_type must be a ParameterSet subclass (a frozen dataclass of quantity() fields)")
    if not dataclasses.is_dataclass(params_type):
        fail(f"params_type {params_type.__name__} must be decorated with @dataclasses.dataclass(frozen=True)")
    if params_type.model != name:
        fail(f"params_type.model is {params_type.model!r} but name is {name!r}; they must be equal")
    for f in dataclasses.fields(params_type):
        if "kind" not in f.metadata:
            fail(f"parameter {f.name} must be declared with quantity(kind, doc)")
    coordinates = getattr(cls, "coordinates", None)
    angular = getattr(cls, "angular", None)
    if (
        not isinstance(coordinates, tuple)
        or not coordinates
        or not all(isinstance(c, str) for c in coordinates)
    ):
        fail("coordinates must be a non-empty tuple of names")
    if not isinstance(angular, tuple) or len(angular) != len(coordinates):
        fail(f"angular must be a tuple of {len(coordinates)} booleans, one per coordinate")
    for attr in ("inputs", "disturbances"):
        value = getattr(cls, attr)
        if not isinstance(value, tuple) or not all(isinstance(x, str) for x in value):
            fail(f"{attr} must be a tuple of names")
    if cls.inputs and "input_matrix" not in cls.hand_written():
        fail(f"declares inputs {', '.join(cls.inputs)} but writes no input_matrix (B)")


def load_model_class(path: str | Path) -> type[ClosedFormModel]:
    """The one ClosedFormModel subclass a model file defines, validated."""
    path = Path(path)
    if path.is_dir():
        raise folder_given(path, "model file")
    if not path.is_file():
        raise missing_file(path, "model file")
    if path.suffix == ".toml":
        # deferred on purpose: SymPy loads only for a text model, not for every model file
        from pendverify.analytic.text_model import load_text_model

        cls = load_text_model(path)
        validate_model_class(cls, path)
        return cls
    if path.suffix.lower() == ".m":
        raise PendverifyError(
            f"{path}: a MATLAB file is read through a declaration: write a text model (.toml) with its "
            f'coordinates, parameters and [matlab] files = ["{path.name}"], and give that '
            "(docs/matlab.md)"
        )
    if path.suffix != ".py":
        kind = suffix_kind(path)
        if kind is not None and kind != "model":
            raise wrong_kind(path, "model file", KINDS[kind].noun, KINDS[kind].given_as)
        raise PendverifyError(f"{path}: a model file is Python source (.py) or a text model (.toml)")
    module = _import(path)
    found = [
        obj
        for obj in vars(module).values()
        if inspect.isclass(obj)
        and issubclass(obj, ClosedFormModel)
        and obj is not ClosedFormModel
        and obj.__module__ == module.__name__
    ]
    if not found:
        # deferred on purpose: SymPy's mechanics loads only for a model file that declares one
        from pendverify.analytic.mechanics_model import model_file_declaration
        from pendverify.analytic.numpy_model import model_file_functions
        from pendverify.analytic.python_dynamics import model_file_dynamics

        declared = (
            model_file_dynamics(module, path)
            or model_file_declaration(module, path)
            or model_file_functions(module, path)
        )
        if declared is not None:
            validate_model_class(declared, path)
            return declared
        raise PendverifyError(
            f"{path}: defines no subclass of pendverify.ClosedFormModel, no functions M, C, G, no METHOD "
            "and no DYNAMICS (examples/cart_pole.py is a complete model file; docs/models.md shows each form)"
        )
    if len(found) > 1:
        raise PendverifyError(
            f"{path}: defines {len(found)} ClosedFormModel subclasses "
            f"({', '.join(c.__name__ for c in found)}); a model file defines exactly one"
        )
    validate_model_class(found[0], path)
    return found[0]


def plugin_parameters(cls: type[ClosedFormModel], model_file: str, params_file: str) -> ParameterSet:
    """A parameter file for a plug-in: its ``model`` key must be the plug-in's name."""
    data = read_parameter_toml(Path(params_file))
    if data.get("model") != cls.name:
        raise ParameterError(
            params_file,
            "model",
            data.get("model"),
            f"must be {cls.name!r}, the model defined in {model_file}",
        )
    return parse_parameter_document(data, params_file, {cls.name: cls.params_type})[2]


def _expected_shapes(model: ClosedFormModel) -> dict[str, tuple[tuple, tuple[int, ...]]]:
    """equation method → (its arguments at the zero state, the shape of its result), from ``INTERFACE``."""
    sizes = {"n": model.nv, "u": len(model.inputs), "w": len(model.disturbances)}
    zero = {
        "q": np.zeros(model.nv),
        "v": np.zeros(model.nv),
        "u": np.zeros(sizes["u"]),
        "w": np.zeros(sizes["w"]),
    }
    return {
        name: (tuple(zero[a] for a in method.args), tuple(sizes[d] for d in method.shape))
        for name, method in INTERFACE.items()
        if method.equation
    }


def check_model_outputs(model: ClosedFormModel) -> None:
    """Evaluate the model's hand-written methods at the zero state: each returns finite numbers of its shape.

    Each value goes through the model boundary (``pendverify.analytic.numeric_values``), as the
    checks read it.  Raises ``UserCodeError`` naming the file defining the class, the method and
    what it returned (or raised), so that a wrong shape is not met later as a broadcasting
    error; a value that leaves double's range (an OverflowError, an infinity, a NaN) is refused
    as the parameter beyond it when there is one (``parameters_overflow``), as the code's otherwise.
    """
    cls = type(model)
    unused = {"input_matrix": not model.inputs, "disturbance_matrix": not model.disturbances}
    for method, (args, _) in _expected_shapes(model).items():
        if method not in cls.hand_written() or unused.get(method):
            continue
        place = f"{where(cls)}: {cls.__name__}.{method}"
        try:
            value = model_value(model, method, *args)
        except KeyboardInterrupt:
            raise
        except OverflowError as exc:
            overflow = parameters_overflow(model, f"{cls.__name__}.{method} at the zero state")
            raise (overflow or UserCodeError(place, f"raised {_described(exc)} at the zero state")) from None
        except ArithmeticError:  # a division by zero at the zero state: the checks meet it at a state
            continue
        except (TypeError, ValueError) as exc:
            user = user_code_error(exc)
            if user is not None:
                raise user from None
            raise UserCodeError(place, f"must return numbers; at the zero state: {exc}") from None
        except PendverifyError:  # the boundary's refusal, or the model's own one-line refusal
            raise
        except BaseException as exc:
            raise (user_code_error(exc) or UserCodeError(place, f"raised {_described(exc)}")) from None
        bad = first_non_finite(value)
        if bad is not None:
            overflow = parameters_overflow(
                model, f"{cls.__name__}.{method}{bad[0]} = {bad[1]} at the zero state"
            )
            raise overflow or UserCodeError(
                place, f"{bad[0]} is {bad[1]} at the zero state: must be a finite number"
            )
