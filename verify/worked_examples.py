"""The worked examples installed with pendverify, and copying one into a folder ready to run.

An example is a model written by hand (a Python model file, and a LaTeX or text model
where one exists), the URDF it is checked against (with xacro and MJCF versions where
they exist), its parameter file and a scene that simulates it.  The files come from the
shipped folders (``pendverify.shipped``) and are listed in the shipped catalogue
``examples/catalogue.toml``.  ``copy_example`` writes them side by side into
one folder; the scene's relative paths (``../examples/cart_pole.py``) become the copies'
names, so the folder runs on its own.
"""

from __future__ import annotations

import re
import shlex
import sys
from dataclasses import dataclass
from pathlib import Path

from pendverify.errors import FileAccessError, UnknownNameError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib
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
    #: sweep files over the model's parameters (``certify --sweep``), where those are shipped
    sweeps: tuple[ShippedFile, ...] = ()

    @property
    def files(self) -> tuple[ShippedFile, ...]:
        written = (self.written_model,) if self.written_model else ()
        return (self.model, *written, self.urdf, *self.descriptions, self.params, self.scene, *self.sweeps)

    @property
    def models(self) -> tuple[ShippedFile, ...]:
        """The model files ``check --analytic`` takes: Python first, then the LaTeX or text one."""
        return (self.model, self.written_model) if self.written_model else (self.model,)


#: the catalogue's roles of a file, by its key
ROLES = {
    "model": "model (Python)",
    "latex": "model (LaTeX)",
    "text": "model (text)",
    "urdf": "URDF",
    "params": "parameters",
    "scene": "scene",
    "sweeps": "sweep",
}
#: a description's role, by the end of its name
DESCRIPTION_ROLES = {".xacro": "xacro", ".xml": "MJCF"}


def _file(spec: str, role: str) -> ShippedFile:
    kind, _, name = spec.partition("/")
    return ShippedFile(kind, name, role)


def _entry(table: dict) -> WorkedExample:
    """One ``[[example]]`` table of the catalogue as a ``WorkedExample``."""
    written = [key for key in ("latex", "text") if key in table]
    return WorkedExample(
        table["name"],
        table["summary"],
        table["dof"],
        **{key: _file(table[key], ROLES[key]) for key in ("model", "urdf", "params", "scene")},
        written_model=_file(table[written[0]], ROLES[written[0]]) if written else None,
        descriptions=tuple(
            _file(spec, DESCRIPTION_ROLES[Path(spec).suffix]) for spec in table.get("descriptions", ())
        ),
        sweeps=tuple(_file(spec, ROLES["sweeps"]) for spec in table.get("sweeps", ())),
    )


def load_catalogue() -> tuple[WorkedExample, ...]:
    """The worked examples of the shipped catalogue (``examples/catalogue.toml``), in its order."""
    text = shipped_file("examples", CATALOGUE).read_text(encoding="utf-8")
    return tuple(_entry(table) for table in tomllib.loads(text)["example"])


#: the shipped file that lists the worked examples
CATALOGUE = "catalogue.toml"
EXAMPLES: tuple[WorkedExample, ...] = load_catalogue()
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
    version, then ``simulate`` of the scene and, where the example has sweeps, ``certify``
    of its first sweep into ``folder/certified``.
    """

    def at(f: ShippedFile) -> str:
        return shlex.quote(str(Path(folder) / f.name))

    pairs = [(m, example.urdf) for m in example.models] + [(example.model, d) for d in example.descriptions]
    checks = [
        f"pendverify check --analytic {at(model)} --urdf {at(robot)} --params {at(example.params)}"
        for model, robot in pairs
    ]
    certified = shlex.quote(str(Path(folder) / "certified"))
    sweeps = [
        f"pendverify certify --sweep {at(sweep)} --workers 2 -o {certified}" for sweep in example.sweeps
    ]
    return [*checks, f"pendverify simulate {at(example.scene)}", *sweeps[:1]]
