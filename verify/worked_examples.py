"""The worked examples installed with pendverify, and copying one into a folder ready to run.

An example is a model written by hand (a Python model file, and a LaTeX or text model and a
declaration of MATLAB ``.m`` files where they exist), the URDF it is checked against (with xacro
and MJCF versions where they exist), its parameter file and a scene that simulates it.  The files
come from the shipped folders (``pendverify.shipped``) and are listed in the shipped catalogue
``examples/catalogue.toml``.

``copy_example`` lays them out in the folder as the package and the repository do, each at
its ``shipped_path``: ``urdf/double_pendulum.urdf``, ``examples/minimal_double_pendulum.toml``,
``scenes/...``.  So the manual's commands, which name the files that way, run unchanged in
that folder, and a scene's relative paths (``../examples/cart_pole.py``) hold as shipped.
"""

from __future__ import annotations

import shlex
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from pendverify.display import REPR_LIMIT, html_table, shortened
from pendverify.documents import parse_toml
from pendverify.errors import FileAccessError, UnknownNameError
from pendverify.shipped import shipped_file, shipped_path


@dataclass(frozen=True)
class ShippedFile:
    """One file of an example: where it is shipped (``kind`` of ``pendverify.shipped``), what it is."""

    kind: str
    name: str
    role: str

    @property
    def source(self) -> Path:
        return shipped_file(self.kind, self.name)

    @property
    def path(self) -> PurePosixPath:
        """Where it is copied to in a folder, and how the manual names it: ``urdf/double_pendulum.urdf``."""
        return shipped_path(self.kind, self.name)


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
    #: the same model derived in MATLAB: a declaration of ``.m`` files, and those files
    matlab_model: ShippedFile | None = None
    matlab_files: tuple[ShippedFile, ...] = ()
    #: the URDF's robot as xacro or MJCF, where those are shipped
    descriptions: tuple[ShippedFile, ...] = ()
    #: sweep files over the model's parameters (``certify --sweep``), where those are shipped
    sweeps: tuple[ShippedFile, ...] = ()

    @property
    def files(self) -> tuple[ShippedFile, ...]:
        models = (*self.models, *self.matlab_files)
        return (*models, self.urdf, *self.descriptions, self.params, self.scene, *self.sweeps)

    @property
    def models(self) -> tuple[ShippedFile, ...]:
        """The model files ``check --analytic`` takes: Python first, then the LaTeX or text one,
        then the declaration of ``.m`` files."""
        return tuple(f for f in (self.model, self.written_model, self.matlab_model) if f is not None)

    def __repr__(self) -> str:
        files = f"{len(self.files)} files: {', '.join(str(f.path) for f in self.files)}"
        head = f"<WorkedExample {self.name!r}, {self.dof} DOF, "
        return head + shortened(files, REPR_LIMIT - len(head) - 1) + ">"

    def _repr_html_(self) -> str:
        """Its files, where each is copied to and what it is, under its name and summary."""
        rows = [(str(f.path), f.role) for f in self.files]
        return html_table(("file", "what it is"), rows, f"{self.name}: {self.summary}")


#: the catalogue's roles of a file, by its key
ROLES = {
    "model": "model (Python)",
    "latex": "model (LaTeX)",
    "text": "model (text)",
    "matlab": "model (MATLAB: a declaration of .m files)",
    "matlab_files": "MATLAB function (.m)",
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
        matlab_model=_file(table["matlab"], ROLES["matlab"]) if "matlab" in table else None,
        matlab_files=tuple(_file(spec, ROLES["matlab_files"]) for spec in table.get("matlab_files", ())),
        descriptions=tuple(
            _file(spec, DESCRIPTION_ROLES[Path(spec).suffix]) for spec in table.get("descriptions", ())
        ),
        sweeps=tuple(_file(spec, ROLES["sweeps"]) for spec in table.get("sweeps", ())),
    )


def load_catalogue() -> tuple[WorkedExample, ...]:
    """The worked examples of the shipped catalogue (``examples/catalogue.toml``), in its order."""
    path = shipped_file("examples", CATALOGUE)
    return tuple(
        _entry(table) for table in parse_toml(path.read_text(encoding="utf-8"), str(path))["example"]
    )


#: the shipped file that lists the worked examples
CATALOGUE = "catalogue.toml"
EXAMPLES: tuple[WorkedExample, ...] = load_catalogue()
NAMES = tuple(e.name for e in EXAMPLES)


def find_example(name: str) -> WorkedExample:
    for example in EXAMPLES:
        if example.name == name:
            return example
    raise UnknownNameError("example", name, NAMES)


def _refuse_outside(folder: Path, target: Path) -> None:
    """Refuse a ``target`` whose way down from ``folder`` leaves it: a file or a link in place of a folder."""
    for part in reversed(target.relative_to(folder).parents[:-1]):  # urdf/, then deeper ones
        here = folder / part
        if here.is_symlink():
            why = f"{here} is a symbolic link; the example is written only inside {folder}"
            raise FileAccessError(str(target), "write", why)
        if here.exists() and not here.is_dir():
            raise FileAccessError(str(target), "write", f"{here} is a file, not a folder")
    if target.is_dir():
        raise FileAccessError(str(target), "write", "it is a folder, not a file")
    if (target.exists() or target.is_symlink()) and not target.is_file():
        raise FileAccessError(str(target), "write", "it is not a regular file")


def _holds(target: Path, data: bytes) -> bool:
    """Whether the file ``target`` (which exists) holds ``data``."""
    try:
        return target.stat().st_size == len(data) and target.read_bytes() == data
    except OSError as exc:
        raise FileAccessError(str(target), "read", exc.strerror or str(exc)) from None


def copy_example(example: WorkedExample, folder: Path, force: bool = False) -> list[Path]:
    """Write the example's files into ``folder`` (created if missing), each at its ``path``; those written.

    A file already there with the same content is left as it is (two examples share
    ``urdf/double_pendulum.urdf``; copying twice changes nothing).  Refuses
    (``FileAccessError``, before writing anything) a ``folder`` that is a file or cannot be
    written, a folder, a link or any other non-file in the place of a file, a file or a
    symbolic link in the place of a subfolder (nothing is written outside ``folder``) and,
    unless ``force``, a file of the same path with other content.  Each file is written atomically.
    """
    from pendverify.atomic import check_output, write_atomic

    check_output(folder, folder=True)
    pending = []
    for f in example.files:
        target = folder / f.path
        _refuse_outside(folder, target)
        data = f.source.read_bytes()
        if target.is_file() and _holds(target, data):
            continue
        pending.append((target, data))
    different = [target for target, _ in pending if target.exists() or target.is_symlink()]
    if different and not force:
        more = f" (and {len(different) - 1} more of the example's files)" if len(different) > 1 else ""
        why = f"it exists already, with other content{more}; give --force to replace"
        raise FileAccessError(str(different[0]), "write", why)
    for target, data in pending:
        write_atomic(target, data)
    return [target for target, _ in pending]


def next_commands(example: WorkedExample, folder: str) -> list[str]:
    """The commands that run the copied example in ``folder`` (as the user named it).

    ``check`` of each model file on the URDF, of the Python model on each xacro or MJCF
    version, then ``simulate`` of the scene and, where the example has sweeps, ``certify``
    of its first sweep into ``folder/certified``.
    """

    def at(f: ShippedFile) -> str:
        return shlex.quote(str(Path(folder) / f.path))

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
