"""A sweep set builds its ``PinocchioSystem`` once and reads its URDF once.

One set of a sweep goes through the whole battery (checks, stress cases, simulations) in
``sweep_task.certify_chunk``, the function a worker runs.  Counted while it runs: systems built
from a description (``PinocchioSystem.for_model``), descriptions read
(``robot.description.load_description``, counted at ``description_format``, which it calls
once per read), XML documents parsed with the strict readers' rules (``defusedxml``'s
``fromstring`` in ``robot.xml_reading.parse_xml``) and URDF texts parsed by urdfdom
(``pinocchio.buildModelFromXML``).  The stress
cases at another g (zero gravity) derive their system from the set's
(``PinocchioSystem.with_gravity``) instead of building one.
"""

from __future__ import annotations

import shutil
from collections import Counter
from pathlib import Path

import pinocchio as pin
import pytest

from pendverify.certify.sweep import load_sweep
from pendverify.certify.sweep_task import certify_chunk
from pendverify.robot import description, xml_reading
from pendverify.robot.system import PinocchioSystem

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SETTINGS = 'mode = "random"\ncount = 2\nseed = 11\nsamples = 50\nduration = 0.2\n[ranges]\nm1 = [0.5, 2.0]\n'


def _sweep(folder: Path, plugin: bool) -> Path:
    sweep = folder / "sweep.toml"
    if not plugin:
        sweep.write_text(f'model = "double_pendulum"\n{SETTINGS}')
        return sweep
    for suffix in ("py", "urdf", "toml"):
        shutil.copy(EXAMPLES / f"hanging_double_pendulum.{suffix}", folder / f"hanging.{suffix}")
    sweep.write_text(f'model = "hanging.py"\nbase = "hanging.toml"\nurdf = "hanging.urdf"\n{SETTINGS}')
    return sweep


def _counting(monkeypatch) -> Counter:
    counts: Counter = Counter()
    for_model = PinocchioSystem.for_model.__func__
    with_gravity = getattr(PinocchioSystem, "with_gravity", None)
    reads = description.description_format
    urdfdom = pin.buildModelFromXML
    xml = xml_reading.DET.fromstring

    def counted(key, fn):
        def call(*args, **kwargs):
            counts[key] += 1
            return fn(*args, **kwargs)

        return call

    monkeypatch.setattr(PinocchioSystem, "for_model", classmethod(counted("built", for_model)))
    if with_gravity is not None:
        monkeypatch.setattr(PinocchioSystem, "with_gravity", counted("derived", with_gravity))
    monkeypatch.setattr(description, "description_format", counted("read", reads))
    monkeypatch.setattr(pin, "buildModelFromXML", counted("parsed", urdfdom))
    monkeypatch.setattr(xml_reading.DET, "fromstring", counted("xml", xml))
    return counts


@pytest.mark.parametrize("plugin", [False, True], ids=["built-in", "model file"])
def test_a_sweep_set_builds_its_system_once_and_reads_its_urdf_once(tmp_path, monkeypatch, plugin):
    sweep = load_sweep(_sweep(tmp_path, plugin))
    settings = sweep.settings.as_dict()
    certify_chunk(sweep.model, sweep.sets[:1], settings, sweep.urdf, sweep.base)  # a worker's first set
    counts = _counting(monkeypatch)
    (result,) = certify_chunk(sweep.model, sweep.sets[1:2], settings, sweep.urdf, sweep.base)
    assert result.passed, result
    assert {i.name.split(":")[0] for i in result.items} == {"check", "stress", "invariant"}, result.items
    assert counts == Counter(built=1, read=1, xml=1, parsed=1, derived=1), f"{plugin=} {counts=}"
