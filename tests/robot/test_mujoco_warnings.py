"""MuJoCo's warnings never leave a ``MUJOCO_LOG.TXT`` in the working folder: they become notes.

The MJCF below uses ``<compiler settotalmass>``, which MuJoCo 3.3+ compiles with a deprecation
warning; compiled by MuJoCo directly in a folder, it leaves ``MUJOCO_LOG.TXT`` there (the
planted case, so the test can fail); read by pendverify, the folder stays clean and the
warning is a note of ``show --robot``.
"""

from __future__ import annotations

from pathlib import Path

import mujoco

from pendverify.cli import main
from pendverify.robot.mujoco_warnings import caught

WARNS = """<mujoco model="warns">
  <compiler settotalmass="2"/>
  <worldbody>
    <body name="link1">
      <joint name="joint1" type="hinge" axis="0 1 0"/>
      <geom type="capsule" size="0.05" fromto="0 0 0 0 0 -1"/>
      <body name="link2" pos="0 0 -1">
        <joint name="joint2" type="hinge" axis="0 1 0"/>
        <geom type="capsule" size="0.05" fromto="0 0 0 0 0 -1"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""
LOG = "MUJOCO_LOG.TXT"
MESSAGE = "compiler attribute 'settotalmass' is deprecated"


def warning_file(folder: Path) -> Path:
    path = folder / "warns.xml"
    path.write_text(WARNS, encoding="utf-8")
    return path


def test_mujoco_alone_writes_its_log_into_the_working_folder(tmp_path, monkeypatch, capfd):
    """The planted case: the file does provoke a warning, and MuJoCo's default handler logs it in the cwd."""
    monkeypatch.chdir(tmp_path)
    mujoco.MjModel.from_xml_path(str(warning_file(tmp_path)))
    assert MESSAGE in (tmp_path / LOG).read_text(encoding="utf-8")
    capfd.readouterr()


def test_show_notes_the_warning_and_leaves_no_log_in_the_working_folder(tmp_path, monkeypatch, capfd):
    monkeypatch.chdir(tmp_path)
    path = warning_file(tmp_path)
    assert main(["show", "--robot", path.name]) == 0
    out, err = capfd.readouterr()  # file descriptors: MuJoCo's C code prints there, not to sys.stdout
    assert not (tmp_path / LOG).exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["warns.xml"]
    [note] = [line for line in out.splitlines() if MESSAGE in line]
    assert note.startswith("note: MuJoCo warns: ")
    assert "WARNING" not in out + err


def test_caught_collects_each_message_once_and_puts_the_handler_back(tmp_path, monkeypatch, capfd):
    monkeypatch.chdir(tmp_path)
    before = mujoco.get_mju_user_warning()
    with caught() as warnings:
        mujoco.MjModel.from_xml_path(str(warning_file(tmp_path)))
        mujoco.MjModel.from_xml_string(WARNS)
    assert len(warnings) == 1 and MESSAGE in warnings[0]
    assert mujoco.get_mju_user_warning() is before
    assert not (tmp_path / LOG).exists()
    capfd.readouterr()
