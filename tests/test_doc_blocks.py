"""Every shell block of the README and the manual runs as written, from a folder outside the clone.

Each page is followed as a newcomer follows it (``tests/doc_blocks.py`` reads it into steps):
in a new temporary folder outside the clone, the worked examples whose files its commands
name (``urdf/double_pendulum.urdf``, ``analytic/params/...``) are copied first with
``pendverify example NAME .``, unless the page copies them itself; then each titled block is
saved, each shell block run with the installed ``pendverify`` (the console script beside
this interpreter, first on ``PATH``), and its exit status and printed output (standard output
and standard error, interleaved) compared with the page's: exit status 0 unless
``EXIT_STATUS`` names another, output as ``doc_blocks.output_difference`` compares it
(figures within the machine's reproducibility, wall times free, the rest verbatim; the
temporary folder's path left out, ``in_the_folder``).

The blocks that cannot run here are listed in ``NOT_RUN`` with the reason; every other block
runs.  A page whose steps take more than ~15 s of CPU is marked ``slow`` in ``SLOW``.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from pendverify.worked_examples import EXAMPLES
from tests.doc_blocks import FENCE, Step, output_difference, page_name, same_number, steps

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
#: the console script of the pendverify installed beside this interpreter
BIN = Path(sys.executable).parent
#: a whole page's commands stop after this long (a hang is a failure, not a stuck CI)
TIMEOUT_S = 600

#: the shell blocks not run, by (page, the start of the block's first line), with the reason
INSTALLS = "installs pendverify into a new virtual environment from the clone (CI's .ci/run does)"
SUITE = "installs the test extra and runs the whole test suite, this test included (CI's .ci/run does)"
NOT_RUN = {
    ("README.md", "python3 -m venv .venv && "): INSTALLS,
    ("README.md", "python3 -m venv .venv-test && "): SUITE,
    ("docs/getting-started.md", "pip install ."): "installs pendverify from the clone (260 MB of downloads)",
    ("docs/getting-started.md", "python3 -m venv .venv && "): INSTALLS,
    ("docs/getting-started.md", "python3 -m venv .venv-test && "): SUITE,
    ("docs/commands/bench.md", "pip install -e '.[bench]'"): (
        "installs the bench extra; the study takes ≈ 20 s to 3 min; my_scene.toml is the reader's"
    ),
    ("docs/commands/bench.md", "pendverify bench explain --quick"): (
        "takes minutes: ≈ 1 min for the sample, far longer for the whole corpus"
    ),
    ("docs/robot-descriptions.md", "pendverify check --analytic arm.py"): (
        "the reader's own files: arm.py, arm.toml and a ROS workspace ws/src"
    ),
    ("docs/robot-descriptions.md", "pip install 'pendverify[erd]'"): "installs the erd extra (131 MB)",
    ("docs/sweeps.md", 'python -c "import signal; from distributed import LocalCluster'): (
        "starts a Dask cluster on port 8786 and certifies 10,000 sets: ≈ 9 min on 2 cores"
    ),
}
#: the blocks whose commands the page says exit with another status than 0, by (page, start of first line)
EXIT_STATUS = {
    ("README.md", "sed 's/\\[h \\* v\\[0\\], 0.0\\]/[h * v[1], 0.0]/' my_pendulum.py"): 1,
    ("docs/getting-started.md", "sed 's/\\[h \\* v\\[0\\], 0.0\\]/[h * v[1], 0.0]/' my_pendulum.py"): 1,
    ("docs/diagnosis.md", "sed 's/& \\\\delta \\\\end{bmatrix}/"): 1,
    ("docs/diagnosis.md", "sed 's/\\\\delta \\\\end{bmatrix}/\\\\delta + m_2 r_2"): 1,
    ("docs/diagnosis.md", "pendverify check --analytic pendulum_kane.py"): 1,
    ("docs/diagnosis.md", "pendverify check --analytic double_pendulum_functions.py"): 1,
    # a model alone whose units agree is not verified against a robot
    ("docs/commands/check.md", "pendverify check --analytic examples/minimal_double_pendulum.py$"): 2,
}
#: pages whose steps take more than ~5 s on a first run (numba compiling, SymPy reading, diagnoses;
#: measured on 2 cores: certify ≈ 20 s, bench certify --quick ≈ 22 s, then ≈ 3 s and ≈ 4 s once the
#: code cache is warm; diagnosis ≈ 22 s, models ≈ 12 s, getting-started ≈ 12 s, text-latex ≈ 9 s,
#: README ≈ 8 s on a shared machine)
SLOW = {
    "docs/certificates.md",
    "docs/commands/bench.md",
    "docs/diagnosis.md",
    "docs/models.md",
    "docs/getting-started.md",
    "docs/text-latex.md",
    "README.md",
}

#: the path the manual names a worked example's file by → the examples that hold it, in catalogue order
EXAMPLES_OF: dict[str, list[str]] = {}
for _example in EXAMPLES:
    for _file in _example.files:
        EXAMPLES_OF.setdefault(str(_file.path), []).append(_example.name)
COPIED_BY_PAGE = re.compile(r"^pendverify example (\w+) \.\s*$", re.M)


def page_steps(path: Path) -> list[Step]:
    return steps(path.read_text(encoding="utf-8"), page_name(path, ROOT))


def names(start: str, first: str) -> bool:
    """Whether a table's entry names a block by its first line: the line starts with the entry's text
    (is it, for a text ending in ``$``: a command that is the start of another's first line)."""
    return first == start[:-1] if start.endswith("$") else first.startswith(start)


def entry(table: dict[tuple[str, str], object], step: Step) -> object | None:
    """The table's value for ``step``: the entry of its page that names it (``names``)."""
    page, first = step.key
    return next((v for (p, start), v in table.items() if p == page and names(start, first)), None)


def runs(step: Step) -> bool:
    return step.file is None and entry(NOT_RUN, step) is None


def examples_to_copy(page: list[Step]) -> list[str]:
    """The worked examples that hold the files the page's commands name, but that the page does not
    copy itself (``pendverify example NAME .``); of several that hold a file, the first listed."""
    commands = "\n".join(s.text for s in page if runs(s))
    chosen = set(COPIED_BY_PAGE.findall(commands))
    copy: list[str] = []
    for word in re.split(r"[\s=]+", commands):
        holders = EXAMPLES_OF.get(word, [])
        if holders and not chosen & set(holders):
            chosen.add(holders[0])
            copy.append(holders[0])
    return copy


def run_in(folder: Path, script: str) -> subprocess.CompletedProcess:
    """``script`` run by bash in ``folder`` (``set -e``), with this pendverify first on ``PATH``."""
    env = {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}"}
    env.pop("PYTHONPATH", None)  # the installed package, as a newcomer has it
    return subprocess.run(
        ["bash", "-e", "-o", "pipefail", "-c", script],
        cwd=folder,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        timeout=TIMEOUT_S,
    )


def in_the_folder(output: str, folder: Path) -> str:
    """``output`` with the temporary folder's absolute path left out: ``FOLDER/my_typo.py`` is ``my_typo.py``.

    The manual cannot know the reader's folder; a file pendverify names by its absolute path is
    written in the manual as a path relative to the folder the commands run in.
    """
    for spelling in {str(folder.resolve()), str(folder)}:
        output = output.replace(spelling + os.sep, "")
    return output


RUN_PAGES = [p for p in PAGES if any(runs(s) for s in page_steps(p))]


@pytest.mark.parametrize(
    "path",
    [pytest.param(p, marks=[pytest.mark.slow] if page_name(p, ROOT) in SLOW else []) for p in RUN_PAGES],
    ids=lambda p: page_name(p, ROOT),
)
def test_every_shell_block_of_the_page_runs_as_written(path, tmp_path):
    assert ROOT not in tmp_path.resolve().parents, "the folder must be outside the clone"
    page = page_steps(path)
    for name in examples_to_copy(page):
        done = run_in(tmp_path, f"pendverify example {shlex.quote(name)} .")
        assert done.returncode == 0, done.stdout
    for step in page:
        where = f"{step.page}:{step.line}"
        if step.file is not None:
            (tmp_path / step.file).write_text(step.text, encoding="utf-8")
            continue
        if not runs(step):
            continue
        done = run_in(tmp_path, step.text)
        status = entry(EXIT_STATUS, step) or 0
        assert done.returncode == status, (
            f"{where}: exit status {done.returncode}, the page says {status}\n{step.text}\n{done.stdout}"
        )
        if step.output is not None:
            why = output_difference(step.output, in_the_folder(done.stdout, tmp_path))
            assert why is None, f"{where}: the output is not the page's: {why}\n{step.text}\n{done.stdout}"


def test_every_table_names_a_block_there_is():
    """Each entry names one block, and no entry of NOT_RUN another's (a stale entry would hide nothing)."""
    blocks = [s for p in PAGES for s in page_steps(p) if s.file is None]
    for table in (NOT_RUN, EXIT_STATUS):
        for (page, start), value in table.items():
            named = [s for s in blocks if s.page == page and names(start, s.key[1])]
            assert len(named) == 1, f"{page}: {len(named)} shell blocks start with {start!r} ({value})"
    assert SLOW <= {page_name(p, ROOT) for p in RUN_PAGES}


def test_the_pages_hold_shell_blocks_and_outputs_to_compare():
    """The reading finds the blocks: the test would pass vacuously otherwise."""
    all_steps = [s for p in PAGES for s in page_steps(p)]
    assert sum(1 for s in all_steps if runs(s)) >= 10
    assert any(s.output for s in all_steps if runs(s) and s.page == "docs/getting-started.md")
    assert any(s.file == "my_pendulum.py" for s in all_steps if s.page == "docs/getting-started.md")


def escaping_blocks(text: str) -> list[str]:
    """The first lines of the blocks ``steps`` would not see as commands but a reader would: a
    block labelled ``bash``, ``shell``, ``zsh`` or ``shell-session``, a prompt outside ``console``."""
    found = []
    for fence in FENCE.finditer(text):
        info, body = fence["info"].strip(), fence["body"]
        shell = info.split()[:1] in (["bash"], ["shell"], ["zsh"], ["shell-session"])
        if shell or (body.startswith("$ ") and info != "console"):
            found.append(body.splitlines()[0])
    return found


def test_no_shell_block_escapes_the_reading():
    """The manual labels commands ``sh`` and prompts ``console``: nothing is skipped unseen."""
    for path in PAGES:
        assert escaping_blocks(path.read_text(encoding="utf-8")) == [], page_name(path, ROOT)
    planted = "```bash\npendverify check\n```\n\n```\n$ pendverify show x.toml\nout\n```\n"
    assert escaping_blocks(planted) == ["pendverify check", "$ pendverify show x.toml"]


# --- the reading and the comparison themselves, on planted differences ------------------------------
PAGE = """Save it:

```python title="model.py"
x = 1
```

```sh
pendverify check --analytic model.py
```

```
crba  3.26e-16  2.44e-14  random #61 q=(-8.46, -4.77)  pass
8 checks on 1 model(s), 402 states (seed 20260301), 1.13 s: all checks pass
```

```console
$ pendverify show model.py
model m
```
"""


def test_a_page_is_read_into_files_commands_and_outputs():
    saved, checked, shown = steps(PAGE, "page.md")
    assert (saved.file, saved.text) == ("model.py", "x = 1\n")
    assert checked.text == "pendverify check --analytic model.py\n" and checked.output.startswith("crba")
    assert (shown.text, shown.output) == ("pendverify show model.py\n", "model m\n")


@pytest.mark.parametrize(
    ("expected", "actual", "same"),
    [
        ("3.26e-16", "8.63e-16", True),  # rounding: the order of magnitude
        ("3.26e-16", "5.00e-15", False),
        ("0.00e+00", "1.00e-17", False),
        ("2.44e-14", "-2.44e-14", False),
        ("-8.46", "-8.47", True),  # 2 significant digits
        ("-8.46", "-8.66", False),
        ("5.60e-01", "5.70e-01", False),
        ("402", "403", False),  # counts, indices, seeds: exact
        ("−0.088", "-0.088", True),
    ],
)
def test_figures_are_compared_within_what_machines_reproduce(expected, actual, same):
    assert same_number(expected, actual) is same


def test_an_output_differs_by_a_word_a_figure_a_line_or_nothing_but_time():
    printed = PAGE.split("```\n")[3]
    assert output_difference(printed, printed.replace("1.13 s", "7.20 s")) is None
    assert output_difference(printed, printed.replace("3.26e-16", "9.1e-16")) is None
    assert "pass" in output_difference(printed, printed.replace("  pass\n", "  FAIL\n"))
    assert "figure 61 is 62" in output_difference(printed, printed.replace("#61", "#62"))
    assert "goes on" in output_difference(printed, printed + "one more\n")
    assert "missing" in output_difference(printed + "one more\n", printed)
    assert output_difference("a\n...\nz\n", "a\nb\nc\nz\n") is None
    assert output_difference("a\n...\nz\n", "a\nb\nc\n") is not None
    assert output_difference("a\n...\nc\n...\nz\n", "a\nb\nc\nd\nz\n") is None
