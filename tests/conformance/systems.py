"""The conformance matrix's systems: chains, their numbers (fixed by ``SEED``) and robot descriptions.

Each system is a serial chain in the convention of ``tests/conformance/derivation.py`` (z up,
every frame equal to the world's at q = 0, pendulums hanging along −z at q = 0, planar ones
turning about y) with one variant of the description:

* ``visual``: the URDF/MJCF draws each link (a cylinder or box) or draws nothing;
* ``damping``: viscous dampers on every joint (URDF ``<dynamics damping>``, MJCF ``damping``) or none;
* ``inertia``: ``"rod"`` (principal moments about the centre of mass) or ``"point"`` (point masses,
  zero inertia tensors);
* ``continuous``: revolute joints written as URDF ``continuous`` (Pinocchio's (cos, sin)
  configuration) rather than ``revolute`` with wide limits;
* ``mjcf``: an MJCF twin is written too (rod variants only: MuJoCo's compiler requires every
  principal moment of a moving body to be positive), with ``armature`` on each joint when
  ``armature`` is set — pendverify copies MuJoCo's ``dof_armature`` into Pinocchio, where it
  adds to M's diagonal, so the hand model's M carries it (``derivation.armature``).

A cart (a link on a prismatic joint) never turns, so its inertia cannot enter the dynamics: it is
a particle in the derivation and the descriptions give it a fixed 0.01 kg·m² tensor.  A rod's
moment about its own long axis is irrelevant in the planar chains (they never spin about it): the
derivation gives it zero and the MJCF writer 1e-6 kg·m², MuJoCo's positivity requirement.  The
Furuta pendulum turns about its arm and about the vertical, so there every moment is a parameter.

Numbers: a ``numpy.random.default_rng(SEED)`` draws each system's parameters, in the order of
``SYSTEMS`` and of each system's parameter names, from the ranges of ``_draw``.
"""

from __future__ import annotations

import dataclasses
import functools
from pathlib import Path

import numpy as np
import sympy as sp

SEED = 20261206
G = 9.81
#: a cart's inertia tensor in the descriptions (it never turns: irrelevant to the dynamics)
CART_INERTIA = 0.01
#: a rod's moment about its own long axis in MJCF (irrelevant in a planar chain; MuJoCo wants > 0)
AXIAL_INERTIA = 1e-6


@dataclasses.dataclass(frozen=True)
class System:
    """A chain (``derivation`` convention), its variant flags and its actuated joints."""

    name: str
    joints: tuple  # ("revolute" | "prismatic", axis, origin along the parent's -z or +x)
    actuated: tuple[bool, ...]
    visual: bool = True
    damping: bool = True
    inertia: str = "rod"
    continuous: bool = False
    mjcf: bool = False
    armature: bool = False
    furuta: bool = False

    @property
    def dof(self) -> int:
        return len(self.joints)

    @property
    def joint_names(self) -> tuple[str, ...]:
        return tuple(f"joint{i + 1}" for i in range(self.dof))

    @property
    def inputs(self) -> tuple[str, ...]:
        return tuple(f"tau{k + 1}" for k in range(sum(self.actuated)))

    def chain(self) -> list[dict]:
        """The chain of ``derivation.kane`` in the parameter names of ``parameter_kinds``."""
        chain = []
        for i, (kind, axis) in enumerate(self.joints):
            k = i + 1
            previous = chain[-1] if chain else None
            if previous is None:
                origin = ("0", "0", "0")
            elif self.furuta:
                origin = (f"l{i}", "0", "0")  # the pendulum's pivot at the arm's end
            elif previous["type"] == "prismatic":
                origin = ("0", "0", "0")  # a hinge on the cart / on the slider
            else:
                origin = ("0", "0", f"-l{i}")
            if kind == "prismatic":
                com, moments = ("0", "0", "0"), None
            elif self.furuta and i == 0:
                com, moments = (f"r{k}", "0", "0"), (f"J{k}", f"I{k}", f"I{k}")  # the arm along +x
            elif self.furuta:
                com, moments = ("0", "0", f"-r{k}"), (f"I{k}", f"K{k}", f"J{k}")  # the pendulum along -z
            else:
                com, moments = ("0", "0", f"-r{k}"), (f"I{k}", f"I{k}", "0")
            if self.inertia == "point":
                moments = None
            chain.append(
                {
                    "type": kind,
                    "axis": axis,
                    "origin": origin,
                    "com": com,
                    "mass": f"m{k}",
                    "inertia": moments,
                    "damping": f"b{k}" if self.damping else None,
                    "actuated": self.actuated[i],
                }
            )
        return chain

    def armatures(self, description: str) -> tuple[str, ...]:
        """The armature parameters a model of this system checked against ``description`` carries."""
        return tuple(f"a{i + 1}" for i in range(self.dof)) if self.armature and description == "mjcf" else ()

    def parameter_kinds(self, description: str = "urdf") -> dict[str, str]:
        """Every parameter the chain (and ``description``'s armature) names, with its pendverify kind."""
        kinds: dict[str, str] = {}
        for joint in self.chain():
            kinds[joint["mass"]] = "mass"
            for c in (*joint["origin"], *joint["com"]):
                name = c.lstrip("-")
                if name != "0":
                    kinds[name] = "length" if name.startswith("l") else "offset"
            for c in joint["inertia"] or ():
                if c != "0":
                    kinds[c] = "inertia"
            if joint["damping"]:
                kinds[joint["damping"]] = "damping"
        # an armature adds to M's diagonal: a rotor inertia (kg·m²) on a hinge, a mass (kg) on a slide
        for a, (kind, _) in zip(self.armatures(description), self.joints, strict=False):
            kinds[a] = "mass" if kind == "prismatic" else "inertia"
        kinds["g"] = "gravity"
        return kinds


R, P = "revolute", "prismatic"
SYSTEMS = {
    s.name: s
    for s in (
        System("single_pendulum", ((R, "y"),), (True,), visual=False, inertia="point"),
        System("cart_pole", ((P, "x"), (R, "y")), (True, False), damping=False, mjcf=True, armature=True),
        System("acrobot", ((R, "y"), (R, "y")), (False, True), continuous=True, mjcf=True),
        System("cart_double_pendulum", ((P, "x"), (R, "y"), (R, "y")), (True, True, True), visual=False),
        System("furuta", ((R, "z"), (R, "x")), (True, True), furuta=True, mjcf=True),
        System("triple_pendulum", ((R, "y"),) * 3, (True,) * 3, inertia="point", continuous=True),
        System("chain5", ((R, "y"),) * 5, (True,) * 5, damping=False),
        System(
            "prr_arm",
            ((P, "z"), (R, "y"), (R, "y")),
            (True, True, True),
            visual=False,
            mjcf=True,
            armature=True,
        ),
    )
}


def _draw(rng: np.random.Generator, name: str, values: dict[str, float]) -> float:
    """One parameter's value: masses 0.3–2 kg, lengths 0.3–1 m, offsets 30–70 % of the link,
    inertias 0.8–1.2 × m l²/12 (an axial one a tenth of
    that, K 0.9–1 × I: the triangle inequality MuJoCo asks), dampers 0.01–0.1, armatures
    0.005–0.02 kg·m² (kg on a slide)."""
    kind, index = name[0], name[1:]
    if kind == "m":
        return rng.uniform(0.3, 2.0)
    if kind == "l":
        return rng.uniform(0.3, 1.0)
    length = values.get(f"l{index}", 0.5)
    if kind == "r":
        return length * rng.uniform(0.3, 0.7)
    if kind == "K":  # the pendulum's moment across its face: at most the hinge's (A + B ≥ C)
        return values[f"I{index}"] * rng.uniform(0.9, 1.0)
    if kind in "IJ":
        return values[f"m{index}"] * length**2 / 12 * rng.uniform(0.8, 1.2) * (0.1 if kind == "J" else 1.0)
    if kind == "b":
        return rng.uniform(0.01, 0.1)
    if kind == "a":
        return rng.uniform(0.005, 0.02)
    raise AssertionError(name)


@functools.cache
def parameters() -> dict[str, dict[str, float]]:
    """Every system's parameter values (``SEED``), each rounded to 6 significant digits."""
    rng = np.random.default_rng(SEED)
    out = {}
    for system in SYSTEMS.values():
        names = [n for n in system.parameter_kinds("mjcf") if n != "g"]
        values: dict[str, float] = {}
        for name in sorted(names, key=lambda n: ("mlrIJKba".index(n[0]), n)):
            values[name] = float(f"{_draw(rng, name, values):.6g}")
        values["g"] = G
        out[system.name] = values
    return out


def _value(expression: str, values: dict[str, float]) -> float:
    return float(sp.sympify(expression).subs({sp.Symbol(k): v for k, v in values.items()}))


def _xyz(strings, values) -> str:
    return " ".join(repr(_value(c, values)) for c in strings)


_AXES = {"x": "1 0 0", "y": "0 1 0", "z": "0 0 1"}


def _moments(joint: dict, values: dict[str, float], axial: float) -> tuple[float, float, float]:
    if joint["type"] == "prismatic":
        return (CART_INERTIA,) * 3
    if joint["inertia"] is None:
        return (0.0, 0.0, 0.0)
    return tuple(_value(c, values) if c != "0" else axial for c in joint["inertia"])


def _link_geometry(joint: dict, values: dict[str, float]) -> tuple[str, str]:
    """(pose "x y z", "r p y") and a URDF geometry element drawing the link (rod to its centre of mass)."""
    if joint["type"] == "prismatic":
        return "0 0 0", "0 0 0", '<box size="0.2 0.1 0.05"/>'
    com = [_value(c, values) for c in joint["com"]]
    length = max(2 * float(np.linalg.norm(com)), 0.05)
    rpy = "0 1.5707963267948966 0" if abs(com[0]) > 0 else "0 0 0"
    half = " ".join(repr(c) for c in com)
    return half, rpy, f'<cylinder radius="0.01" length="{length!r}"/>'


def urdf(system: System) -> str:
    """The URDF of ``system`` with the numbers of ``parameters()``."""
    values = parameters()[system.name]
    lines = ['<?xml version="1.0"?>', f'<robot name="{system.name}">', '  <link name="base"/>']
    parent = "base"
    for i, joint in enumerate(system.chain()):
        name, link = system.joint_names[i], f"link{i + 1}"
        kind = joint["type"]
        if kind == "revolute" and system.continuous:
            kind = "continuous"
        lines += [
            f'  <joint name="{name}" type="{kind}">',
            f'    <parent link="{parent}"/>',
            f'    <child link="{link}"/>',
            f'    <origin xyz="{_xyz(joint["origin"], values)}" rpy="0 0 0"/>',
            f'    <axis xyz="{_AXES[joint["axis"]]}"/>',
        ]
        if kind != "continuous":
            lines.append('    <limit lower="-1e9" upper="1e9" effort="1e9" velocity="1e9"/>')
        if joint["damping"]:
            lines.append(f'    <dynamics damping="{values[joint["damping"]]!r}"/>')
        lines.append("  </joint>")
        ixx, iyy, izz = _moments(joint, values, 0.0)
        lines += [
            f'  <link name="{link}">',
            "    <inertial>",
            f'      <origin xyz="{_xyz(joint["com"], values)}" rpy="0 0 0"/>',
            f'      <mass value="{values[joint["mass"]]!r}"/>',
            f'      <inertia ixx="{ixx!r}" ixy="0" ixz="0" iyy="{iyy!r}" iyz="0" izz="{izz!r}"/>',
            "    </inertial>",
        ]
        if system.visual:
            pos, rpy, geometry = _link_geometry(joint, values)
            lines += [
                "    <visual>",
                f'      <origin xyz="{pos}" rpy="{rpy}"/>',
                f"      <geometry>{geometry}</geometry>",
                "    </visual>",
            ]
        lines.append("  </link>")
        parent = link
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def mjcf(system: System) -> str:
    """The MJCF twin of ``urdf(system)`` (rod variants only; ``armature`` when the system has it)."""
    assert system.mjcf and system.inertia == "rod", system
    values = parameters()[system.name]
    body_lines: list[str] = []
    indent = "    "
    for i, joint in enumerate(system.chain()):
        kind = "hinge" if joint["type"] == "revolute" else "slide"
        extra = ""
        if joint["damping"]:
            extra += f' damping="{values[joint["damping"]]!r}"'
        if system.armature:
            extra += f' armature="{values[f"a{i + 1}"]!r}"'
        ixx, iyy, izz = _moments(joint, values, AXIAL_INERTIA)
        body_lines += [
            f'{indent}<body name="link{i + 1}" pos="{_xyz(joint["origin"], values)}">',
            f'{indent}  <joint name="{system.joint_names[i]}" type="{kind}" '
            f'axis="{_AXES[joint["axis"]]}"{extra}/>',
            f'{indent}  <inertial pos="{_xyz(joint["com"], values)}" mass="{values[joint["mass"]]!r}" '
            f'diaginertia="{ixx!r} {iyy!r} {izz!r}"/>',
        ]
        if system.visual:
            body_lines.append(
                f'{indent}  <geom type="sphere" pos="{_xyz(joint["com"], values)}" size="0.02" '
                'contype="0" conaffinity="0"/>'
            )
        indent += "  "
    for i in reversed(range(system.dof)):
        body_lines.append("    " + "  " * i + "</body>")
    return "\n".join(
        [
            f'<mujoco model="{system.name}">',
            '  <compiler angle="radian" inertiafromgeom="false"/>',
            f'  <option gravity="0 0 {-G!r}"/>',
            "  <worldbody>",
            *body_lines,
            "  </worldbody>",
            "</mujoco>",
            "",
        ]
    )


def parameter_file(system: System, description: str) -> str:
    """The pendverify parameter file (TOML) of ``system``'s model for ``description``."""
    values = parameters()[system.name]
    lines = [f'model = "{system.name}"', f'name = "{system.name}"', "", "[parameters]"]
    lines += [f"{name} = {values[name]!r}" for name in system.parameter_kinds(description)]
    return "\n".join(lines) + "\n"


def descriptions(system: System) -> tuple[str, ...]:
    """The robot-description formats written for ``system``."""
    return ("urdf", "mjcf") if system.mjcf else ("urdf",)


def write_description(system: System, description: str, folder: Path) -> Path:
    """Write ``system``'s URDF or MJCF into ``folder`` (a fixed file name: the code cache keys on names)."""
    path = folder / (f"{system.name}.urdf" if description == "urdf" else f"{system.name}.mjcf.xml")
    path.write_text(urdf(system) if description == "urdf" else mjcf(system))
    return path
