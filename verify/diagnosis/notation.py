"""An expression in the model's own notation, and where an entry sits in the model's source.

* a LaTeX model file (``notation = "latex"``): LaTeX with the file's own symbols — each
  model name printed as the first key of the file's ``[symbols]`` table that reads as it
  (``\\theta_1`` for theta1), and each shorthand of the table (``\\delta`` = I2 + m2*r2**2)
  put back where its expression stands (SymPy's ``subs``, which also finds 2·I2 + 2·m2·r2²
  as 2·δ); the location is the file and the equation's key;
* a text model file in SymPy syntax: SymPy's own printing over the file's names;
* a declaration of ``.m`` files (``[matlab]``): MATLAB syntax (``sympy.octave_code``), and the
  location of an entry the ``.m`` file's line where it is written (``MatlabSource.line_of``);
* a repaired entry of either kind of file is the user's own text of the entry with the fewest
  terms changed, each changed term printed as above (``pendverify.diagnosis.source_edit``);
* a Python class: the same printing, which is a Python expression over the class's names;
  the location is the source file and ``Class.method``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

from pendverify.analytic.forms import entry_position
from pendverify.analytic.source_file import where
from pendverify.analytic.text_model import METHODS
from pendverify.diagnosis.source_edit import UNREADABLE, SourceText, minimal_edit

#: method → the key of a text model file that gives it
TEXT_KEYS = {method: key for key, (method, _) in METHODS.items()}


@dataclass
class Notation:
    """How the model writes its expressions (module docstring)."""

    kind: str  # "latex", "sympy" or "python"
    source: str
    class_name: str
    derived: dict = field(default_factory=dict)  # text file: key → how it was computed from others
    names: dict = field(default_factory=dict)  # LaTeX: symbol → its LaTeX
    shorthands: list = field(default_factory=list)  # LaTeX: (expression, its symbol), largest first
    spec: object = None  # a text model file's spec (``TextModelSpec``), None for a class
    _source: list = field(default_factory=list, repr=False)  # the file's SourceText, once read

    @classmethod
    def of(cls, model_cls) -> Notation:
        spec = getattr(model_cls, "text_spec", None)
        if spec is None:
            return cls("python", where(model_cls), model_cls.__name__)
        kind = "matlab" if spec.matlab is not None else spec.notation
        notation = cls(kind, str(spec.path), model_cls.__name__, dict(spec.derived), spec=spec)
        for key, value in spec.latex_symbols.items():
            value = sp.sympify(value)
            if isinstance(value, sp.Symbol):
                notation.names.setdefault(value, key)
            elif value.free_symbols:
                stand_in = sp.Symbol(f"shorthand{len(notation.shorthands)}")
                notation.names[stand_in] = key
                notation.shorthands.append((value, stand_in))
        notation.shorthands.sort(key=lambda pair: -sp.count_ops(pair[0]))
        return notation

    def render(self, expr) -> str:
        """The expression as the model's source would write it."""
        if self.kind == "matlab":
            return sp.octave_code(expr)
        if self.kind != "latex":
            return str(expr)
        forms = []
        for form in (expr, sp.factor_terms(expr)):  # 2·I2 + 2·m2·r2² is 2·δ once factored
            for value, stand_in in self.shorthands:
                form = form.subs(value, stand_in)
            forms.append(form)
        return sp.latex(min(forms, key=sp.count_ops), symbol_names=self.names)

    def entry_edit(self, method: str, index: int, old, new) -> tuple[str, str]:
        """(the entry as the source writes it, the repaired entry): for a text model file, the file's
        own text of the entry and that text with the fewest terms changed (``source_edit``); for a
        class, a key derived from others, or when the text is not found, both printed whole."""
        whole = self.render(old), self.render(new)
        key = TEXT_KEYS.get(method, method)
        if (
            self.spec is None
            or key in self.derived
            or key not in self.spec.equations
            or self.kind == "matlab"
        ):
            return whole
        if not self._source:
            try:
                self._source.append(SourceText(self.spec))
            except UNREADABLE:  # the file is gone or changed since it was read
                self._source.append(None)
        source = self._source[0]
        if source is None:
            return whole
        value = self.spec.equations[key]
        position = _position(method, value, index)
        written = source.entry_text(key, position, old)
        if written is None:
            return whole
        edited = minimal_edit(source, written, old, new, self.render)
        return written, edited if edited is not None else whole[1]

    def line_edit(self, changes: dict):
        """For a model of ``.m`` files, the one line of a file whose change is the confirmed repair
        ``changes`` ({(method, flat index): (old, new)}) (``pendverify.diagnosis.matlab_line_edit``);
        None for other models, or when no single line makes exactly those changes."""
        if self.kind != "matlab":
            return None
        from pendverify.diagnosis.matlab_line_edit import line_edit  # deferred: a .m model's alone

        entries = {}
        for (method, index), pair in changes.items():
            key = TEXT_KEYS.get(method, method)
            value = self.spec.equations.get(key)
            if key in self.derived or value is None or index is None:
                return None
            position = _position(method, value, index)
            entries[key, position] = pair
        angles = tuple(s for s, angle in zip(self.spec.symbols["q"], self.spec.angular, strict=True) if angle)
        return line_edit(self.spec.matlab, entries, angles)

    def location(self, method: str, label: str, index: int | None = None) -> str:
        """Where the entry sits: the file, the key (or Class.method) and the entry; for an entry an
        ``.m`` file writes (flat ``index``), that file and its line."""
        if self.kind == "python":
            return f"{self.source}, {self.class_name}.{method}, entry {label}"
        key = TEXT_KEYS.get(method, method)
        if (
            self.kind == "matlab"
            and index is not None
            and key in self.spec.equations
            and key not in self.derived
        ):
            value = self.spec.equations[key]
            position = _position(method, value, index)
            found = self.spec.matlab.line_of(key, position)
            if found is not None:
                path, line = found
                return f"{path}, line {line}, entry {label} (key {key} of {self.source})"
        how = f" (derived: {self.derived[key]})" if key in self.derived else ""
        return f"{self.source}, key {key}{how}, entry {label}"


def _position(method: str, value, index: int) -> tuple[int, ...]:
    """Where the flat ``index`` of ``method``'s entries sits in the equation's ``value``: (row,
    column) or (row,) of a matrix, () of a scalar (``forms.entry_position``)."""
    return entry_position(method, value.shape, index) if isinstance(value, sp.MatrixBase) else ()
