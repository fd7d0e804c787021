"""A sweep set builds its ``PinocchioSystem`` once and parses its URDF once.

One set of a sweep goes through the whole battery (checks, stress cases, simulations) in
``sweep_task.certify_chunk``, the function a worker runs.  Counted while it runs: systems built
from a description (``PinocchioSystem.for_model``), descriptions read
(``robot.description.load_description``, counted at ``format_of``, which it calls once per
read), XML documents parsed by pendverify (its one parse, ``robot.xml_reading._parse``), every
other XML parser Python offers (expat parsers created, ElementTree's and defusedxml's parsers and
``fromstring``/``parse``/``iterparse``, lxml's if it is installed: none may run but the expat
parser of pendverify's own parse) and URDF texts parsed by urdfdom
(``pinocchio.buildModelFromXML``, the build of the system's model).  The stress cases at another
g (zero gravity) derive their system from the set's (``PinocchioSystem.with_gravity``) instead of
building one.  Writing the set's certificate (``issue.write_sweep_certificates``, in the main
process) parses nothing: the bundle names the description's file by the format the battery read.
"""

from __future__ import annotations

import shutil
import xml.etree.ElementTree as ET
from collections import Counter
from pathlib import Path
from xml.parsers import expat

import defusedxml.ElementTree as DET
import pinocchio as pin
import pytest

from pendverify.certify.issue import write_sweep_certificates
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
    reads = description.format_of
    urdfdom = pin.buildModelFromXML
    xml = xml_reading._parse

    def counted(key, fn):
        def call(*args, **kwargs):
            counts[key] += 1
            return fn(*args, **kwargs)

        return call

    monkeypatch.setattr(PinocchioSystem, "for_model", classmethod(counted("built", for_model)))
    if with_gravity is not None:
        monkeypatch.setattr(PinocchioSystem, "with_gravity", counted("derived", with_gravity))
    monkeypatch.setattr(description, "format_of", counted("read", reads))
    monkeypatch.setattr(pin, "buildModelFromXML", counted("parsed", urdfdom))
    monkeypatch.setattr(xml_reading, "_parse", counted("xml", xml))
    monkeypatch.setattr(expat, "ParserCreate", counted("expat", expat.ParserCreate))
    for module, name in _OTHER_PARSERS:
        monkeypatch.setattr(module, name, counted("other xml", getattr(module, name)))
    return counts


_OTHER_PARSERS = [(m, n) for m in (ET, DET) for n in ("XMLParser", "fromstring", "parse", "iterparse", "XML")]
try:
    from lxml import etree as LXML
except ImportError:  # lxml is optional: without it nothing can call it
    pass
else:
    _OTHER_PARSERS += [(LXML, n) for n in ("XMLParser", "fromstring", "parse", "iterparse", "XML")]


@pytest.mark.parametrize("plugin", [False, True], ids=["built-in", "model file"])
def test_a_sweep_set_builds_its_system_once_and_reads_its_urdf_once(tmp_path, monkeypatch, plugin):
    sweep = load_sweep(_sweep(tmp_path, plugin))
    settings = sweep.settings.as_dict()
    certify_chunk(sweep.model, sweep.sets[:1], settings, sweep.urdf, sweep.base)  # a worker's first set
    counts = _counting(monkeypatch)
    (result,) = certify_chunk(sweep.model, sweep.sets[1:2], settings, sweep.urdf, sweep.base)
    assert result.passed, result
    assert {i.name.split(":")[0] for i in result.items} == {"check", "stress", "invariant"}, result.items
    assert write_sweep_certificates(sweep, [result], tmp_path / "out") == 1
    assert (tmp_path / "out" / f"{result.name}.urdf").read_text() == result.urdf
    # one expat parser: the one ``_parse`` runs; "other xml" absent
    expected = Counter(built=1, read=1, xml=1, expat=1, parsed=1, derived=1)
    assert counts == expected, f"{plugin=} {counts=}"
