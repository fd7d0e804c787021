"""The worked examples installed with pendverify, and copying one into a folder ready to run.

An example is a model written by hand (a Python model file, and a LaTeX or text model
where one exists), the URDF it is checked against (with xacro and MJCF versions where
they exist), its parameter file and a scene that simulates it.  The files come from the
shipped folders (``pendverify.shipped``).  ``copy_example`` writes them side by side into
one folder; the scene's relative paths (``../examples/cart_pole.py``) become the copies'
names, so the folder runs on its own.
"""

from __future__ import annotations

import re
import shlex
from dataclasses import dataclass
from pathlib import Path

from pendverify.errors import FileAccessError, UnknownNameError
from pendverify.shipped import shipped_file

#: a scene's keys that name a file relative to the scene
SCENE_PATH_KEYS = ("model", "params", "urdf")
#: one such key's line, when its value goes up out of the scene's folder: ``model = "../examples/x.py"``
_SCENE_PATH_LINE = re.compile(
    rf'^(?P<key>{"|".join(SCENE_PATH_KEYS)})(?P<eq>\s*=\s*)"(?P<path>\.\./[^"]+)"', re.MULTILINE
)


@dataclass(frozen=True)
class ShippedFile:
    """One file of an example: where it is shipped (``kind`` of ``pendverify.shipped``), what it is."""

    kind: str
    name: str
    role: str

    @property
    def source(self) -> Path:
        return shipped_file(self.kind, self.name)


@dataclass(frozen=True)
class WorkedExample:
    name: str
    summary: str
    dof: int
    #: the Python model file, given to ``check --analytic``
    model: ShippedFile
    urdf: ShippedFile
    params: ShippedFile
    scene: ShippedFile
    #: the same model as LaTeX or text, where one is shipped
    written_model: ShippedFile | None = None
    #: the URDF's robot as xacro or MJCF, where those are shipped
    descriptions: tuple[ShippedFile, ...] = ()

    @property
    def files(self) -> tuple[ShippedFile, ...]:
        written = (self.written_model,) if self.written_model else ()
        return (self.model, *written, self.urdf, *self.descriptions, self.params, self.scene)

    @property
    def models(self) -> tuple[ShippedFile, ...]:
        """The model files ``check --analytic`` takes: Python first, then the LaTeX or text one."""
        return (self.model, self.written_model) if self.written_model else (self.model,)


def _plugin(name: str, summary: str, dof: int, scene: str, latex: bool = False) -> WorkedExample:
    """An example whose model, URDF and parameters are all ``examples/NAME.*`` (``NAME_latex.toml``)."""
    return WorkedExample(
        name,
        summary,
        dof,
        model=ShippedFile("examples", f"{name}.py", "model (Python)"),
        written_model=ShippedFile("examples", f"{name}_latex.toml", "model (LaTeX)") if latex else None,
        urdf=ShippedFile("examples", f"{name}.urdf", "URDF"),
        params=ShippedFile("examples", f"{name}.toml", "parameters"),
        scene=ShippedFile("scenes", scene, "scene"),
    )


EXAMPLES: tuple[WorkedExample, ...] = (
    _plugin(
        "cart_pole",
        "a cart-pole with an inertial pole, friction on the cart and at the pivot",
        2,
        "cart_pole_lqr_push.toml",
        latex=True,
    ),
    _plugin(
        "furuta_pendulum",
        "a Furuta (rotary inverted) pendulum with full body inertias: not planar",
        2,
        "furuta_arm_turning.toml",
    ),
    _plugin(
        "triple_pendulum",
        "a triple pendulum in absolute angles from hanging, with joint friction",
        3,
        "damped_triple_pendulum.toml",
    ),
    _plugin(
        "hanging_double_pendulum",
        "a double pendulum in absolute angles from hanging (non-diagonal D and B)",
        2,
        "hanging_double_pendulum_swing.toml",
    ),
    WorkedExample(
        "minimal_double_pendulum",
        "the least a hand derivation gives (M, C, H, V, D, B) of a double pendulum",
        2,
        model=ShippedFile("examples", "minimal_double_pendulum.py", "model (Python)"),
        written_model=ShippedFile("examples", "minimal_double_pendulum_text.toml", "model (text)"),
        urdf=ShippedFile("urdf", "double_pendulum.urdf", "URDF"),
        params=ShippedFile("examples", "minimal_double_pendulum.toml", "parameters"),
        scene=ShippedFile("scenes", "minimal_double_pendulum_release.toml", "scene"),
    ),
    WorkedExample(
        "double_pendulum",
        "reference system: the fixed-base actuated double pendulum",
        2,
        model=ShippedFile("models", "double_pendulum.py", "model (Python)"),
        written_model=ShippedFile("examples", "double_pendulum_latex.toml", "model (LaTeX)"),
        urdf=ShippedFile("urdf", "double_pendulum.urdf", "URDF"),
        descriptions=(
            ShippedFile("examples", "double_pendulum.xacro", "xacro"),
            ShippedFile("examples", "double_pendulum.mjcf.xml", "MJCF"),
        ),
        params=ShippedFile("params", "double_pendulum.toml", "parameters"),
        scene=ShippedFile("scenes", "damped_double_pendulum.toml", "scene"),
    ),
    WorkedExample(
        "cart_double_pendulum",
        "reference system: the double inverted pendulum on a cart",
        3,
        model=ShippedFile("models", "cart_double_pendulum.py", "model (Python)"),
        written_model=ShippedFile("examples", "cart_double_pendulum_latex.toml", "model (LaTeX)"),
        urdf=ShippedFile("urdf", "cart_double_pendulum.urdf", "URDF"),
        params=ShippedFile("params", "cart_double_pendulum.toml", "parameters"),
        scene=ShippedFile("scenes", "cart_lqr_push.toml", "scene"),
    ),
)

NAMES = tuple(e.name for e in EXAMPLES)


def find_example(name: str) -> WorkedExample:
    for example in EXAMPLES:
        if example.name == name:
            return example
    raise UnknownNameError("example", name, NAMES)


def scene_for_folder(text: str, copied: set[str]) -> str:
    """A shipped scene's text with its relative paths (``../examples/X``) turned into ``X``.

    ``copied`` is the set of file names copied beside it; a path to any other file is a
    mistake in the catalogue, and raises ``ValueError`` naming it.
    """

    def local(match: re.Match) -> str:
        name = Path(match["path"]).name
        if name not in copied:
            raise ValueError(f"the scene's {match['key']} {match['path']!r} is not one of the copied files")
        return f'{match["key"]}{match["eq"]}"{name}"'

    return _SCENE_PATH_LINE.sub(local, text)


def copy_example(example: WorkedExample, folder: Path, force: bool = False) -> list[Path]:
    """Write the example's files into ``folder`` (created if missing); the paths written, in order.

    Refuses (``FileAccessError``, before writing anything) a ``folder`` that is a file or
    cannot be written, a folder in the place of a file to be written, and, unless ``force``,
    a file of the same name as one to be written.  Each file is written atomically.
    """
    from pendverify.atomic import check_output, write_atomic

    check_output(folder, folder=True)
    targets = [folder / f.name for f in example.files]
    for target in targets:
        if target.is_dir():
            raise FileAccessError(str(target), "write", "it is a folder, not a file")
    present = [t for t in targets if t.exists() or t.is_symlink()]
    if present and not force:
        more = f" (and {len(present) - 1} more of the example's files)" if len(present) > 1 else ""
        raise FileAccessError(str(present[0]), "write", f"it exists already{more}; give --force to replace")
    copied = {f.name for f in example.files}
    for f, target in zip(example.files, targets, strict=True):
        data = f.source.read_bytes()
        if f is example.scene:
            data = scene_for_folder(data.decode("utf-8"), copied).encode("utf-8")
        write_atomic(target, data)
    return targets


def next_commands(example: WorkedExample, folder: str) -> list[str]:
    """The commands that run the copied example in ``folder`` (as the user named it).

    ``check`` of each model file on the URDF, of the Python model on each xacro or MJCF
    version, then ``simulate`` of the scene.
    """

    def at(f: ShippedFile) -> str:
        return shlex.quote(str(Path(folder) / f.name))

    pairs = [(m, example.urdf) for m in example.models] + [(example.model, d) for d in example.descriptions]
    checks = [
        f"pendverify check --analytic {at(model)} --urdf {at(robot)} --params {at(example.params)}"
        for model, robot in pairs
    ]
    return [*checks, f"pendverify simulate {at(example.scene)}"]
