"""The conformance matrix: each sampled cell runs its command on its system's model and description.

A cell passes when the command's exit status is the one ``matrix.expected_exit`` gives (0 on the
true model; 1 with the planted entry named for ``check planted``; 2 with a one-line refusal
where the table says the command does not apply) and it printed no traceback.  A cell that
exits 3, raises, or exits otherwise fails with the command line and the last lines printed, so
the failure names what to run to see it again.  ``test_the_matrix_is_what_it_says`` prints the
product's size and the sample's, and checks the sample covers every (system, command) and
(format, command) pair.
"""

from __future__ import annotations

import json
import os
import shlex

import pytest

from tests.conformance.formats import FORMATS, Model
from tests.conformance.matrix import (
    COMMANDS,
    MODEL_FREE,
    Cell,
    expected_exit,
    expected_names,
    full_product,
    plant_for,
    planted_refusal,
    sample,
    selected,
    summary,
)
from tests.conformance.runner import Files, command_lines, run
from tests.conformance.systems import SYSTEMS

pytestmark = pytest.mark.conformance

CELLS = selected()


def _log(cell: Cell, argv: list[str], got, expected: int, printed: str) -> None:
    """One JSON line per command line to ``PENDVERIFY_CONFORMANCE_LOG`` when it is set (for a
    report of every failing cell grouped by its message)."""
    path = os.environ.get("PENDVERIFY_CONFORMANCE_LOG")
    if path:
        lines = [line for line in printed.splitlines() if line.strip()]
        record = {"cell": cell.id, "argv": argv, "exit": got, "expected": expected, "last": lines[-1:]}
        with open(path, "a", encoding="utf-8") as f:
            f.write(json.dumps(record) + "\n")


def _tail(text: str, lines: int = 4) -> str:
    return "\n".join(text.strip().splitlines()[-lines:])


@pytest.mark.parametrize("cell", CELLS, ids=[c.id for c in CELLS])
def test_cell(cell: Cell, tmp_path, signing_keys, capsys):
    fmt = FORMATS.get(cell.format)
    if fmt is not None and fmt.missing() is not None:
        pytest.skip(fmt.missing())
    system = SYSTEMS[cell.system]
    plant = plant_for(cell.system) if cell.command == "check planted" else None
    files = Files(tmp_path, system, cell.format, cell.description, Model(system, cell.description, plant))
    status, reason = expected_exit(cell.format, cell.command, cell.description)
    refusal = plant and planted_refusal(cell.format, plant, cell.system)
    if refusal:
        status, reason = refusal
    for argv in command_lines(cell.command, files, signing_keys):
        got, printed = run(argv, capsys)
        where = f"{cell.id}: pendverify {shlex.join(argv)} (files in {tmp_path})"
        _log(cell, argv, got, status, printed)
        assert got == status, f"{where}: exit {got}, expected {status} ({reason}):\n{_tail(printed)}"
        assert "Traceback" not in printed, f"{where}: printed a traceback:\n{_tail(printed, 12)}"
        if status == 2:
            errors = [line for line in printed.splitlines() if line.startswith("pendverify: error:")]
            assert len(errors) == 1, f"{where}: a refusal is one 'pendverify: error:' line:\n{_tail(printed)}"
            assert not refusal or "key 'H'" in errors[0], f"{where}: the refusal names H:\n{errors[0]}"
        if plant is not None and not refusal:
            names = expected_names(cell.format, plant)
            diagnosis = [line for line in printed.splitlines() if line.startswith("diagnosis")]
            assert not names or any(n in line for line in diagnosis for n in names), (
                f"{where}: planted {plant}, expected one of {names} in a diagnosis line; got:\n"
                + "\n".join(diagnosis[:4])
            )


def test_the_matrix_is_what_it_says():
    """The sizes are printed (``-s`` shows them; the session summary repeats them), the sample covers
    every (system, command) and (format, command) pair, and it is a subset of the full product."""
    print(summary())
    cells = sample()
    full = {c.id for c in full_product()}
    assert {c.id for c in cells} <= full
    for command in COMMANDS:
        ran = [c for c in cells if c.command == command]
        assert {c.system for c in ran} == set(SYSTEMS), command
        if command not in MODEL_FREE:
            assert {c.format for c in ran} == set(FORMATS), command
