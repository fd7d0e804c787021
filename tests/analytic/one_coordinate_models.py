"""A single pendulum and a cart, one coordinate each, written in every form a model file takes.

The pendulum: a point mass m on a massless rod of length l below a continuous hinge about y,
θ from hanging down, viscous damping b at the hinge, a torque τ:

    M = m l²,  C = 0,  H = m g l sin θ  (V = −m g l cos θ),  D = b,  B = 1

(the bob at l(sin θ, 0, −cos θ) after the hinge's rotation about y; gravity −g z).  The cart:
mass m on a prismatic joint along the unit axis (3/5, 0, 4/5), a position x, damping b, a force F:
M = m, C = 0, H = 4 m g / 5 (the height is 4x/5), D = b, B = 1.  Each ``FORMS`` entry is a
model file (suffix, text) and a planted error: (old, new, a check it fails, the entry the
diagnosis names).  Every 1 × 1 matrix is written as a matrix (``[["m*l**2"]]``, a ``bmatrix``),
every one-entry vector as a vector.
"""

from __future__ import annotations

PEND_URDF = """<robot name="pend"><link name="base"/>
  <joint name="hinge" type="continuous"><parent link="base"/><child link="bob"/><axis xyz="0 1 0"/>
    <dynamics damping="0.1"/></joint>
  <link name="bob"><inertial><origin xyz="0 0 -0.5"/><mass value="2.0"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link></robot>
"""
PEND_PARAMS = 'model = "pend"\nname = "urdf"\n[parameters]\nm = 2.0\nl = 0.5\nb = 0.1\ng = 9.81\n'
CART_URDF = """<robot name="cart"><link name="base"/>
  <joint name="slider" type="prismatic"><parent link="base"/><child link="cart"/><axis xyz="0.6 0 0.8"/>
    <limit lower="-10" upper="10" effort="100" velocity="10"/><dynamics damping="0.3"/></joint>
  <link name="cart"><inertial><origin xyz="0 0 0"/><mass value="1.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link></robot>
"""
CART_PARAMS = 'model = "cart"\nname = "urdf"\n[parameters]\nm = 1.5\nb = 0.3\ng = 9.81\n'

_TABLES = """
[coordinates]
theta = "angle"

[parameters]
m = { kind = "mass", unit = "kg" }
l = { kind = "length", unit = "m" }
b = { kind = "damping", unit = "N·m·s/rad" }
g = { kind = "gravity", unit = "m/s²" }

[urdf]
joints = ["hinge"]
"""


def _text(body: str, inputs: str = '["tau"]', notation: str = "") -> str:
    head = f'name = "pend"\n{notation}inputs = {inputs}\n' if inputs else f'name = "pend"\n{notation}'
    return head + body.strip("\n") + "\n" + _TABLES


def _latex(body: str, inputs: str = '["tau"]') -> str:
    return _text(body, inputs, 'notation = "latex"\n')


_DECLARATION = """
DECLARATION = {{
    "name": "pend",
    "dynamics": "{signature}",
    "coordinates": {{"theta": "angle"}},
    {inputs}"parameters": {{
        "m": {{"kind": "mass"}}, "l": {{"kind": "length"}},
        "b": {{"kind": "damping"}}, "g": {{"kind": "gravity"}},
    }},
    "urdf": {{"joints": ["hinge"]}},
    {B}"D": [["b"]],
}}
"""


def _dynamics(code: str, signature: str, inputs: bool = True) -> str:
    declaration = _DECLARATION.format(
        signature=signature,
        inputs='"inputs": ["tau"],\n    ' if inputs else "",
        B='"B": [["1"]],\n    ' if inputs else "",
    )
    return "import math\n\n\n" + code.strip("\n") + "\n\n\n" + declaration


_MECHANICS_DECLARATION = """
DECLARATION = {
    "name": "pend",
    "coordinates": {"theta": "angle"},
    "inputs": ["tau"],
    "parameters": {
        "m": {"kind": "mass"}, "l": {"kind": "length"}, "b": {"kind": "damping"}, "g": {"kind": "gravity"}
    },
    "urdf": {"joints": ["hinge"]},
}
"""

_LAGRANGE = """
import sympy as sp
from sympy.physics.mechanics import LagrangesMethod, Lagrangian, Particle, Point, ReferenceFrame
from sympy.physics.mechanics import dynamicsymbols

theta, tau = dynamicsymbols("theta tau")
m, l, b, g = sp.symbols("m l b g")
N = ReferenceFrame("N")
A = N.orientnew("A", "Axis", (theta, N.z))
O = Point("O")
O.set_vel(N, 0)
P = O.locatenew("P", -l * A.y)  # the bob, l below the hinge when theta = 0
P.v2pt_theory(O, N, A)
bob = Particle("bob", P, m)
bob.potential_energy = m * g * P.pos_from(O).dot(N.y)
loads = [(A, (tau - b * theta.diff()) * N.z)]
METHOD = LagrangesMethod(Lagrangian(N, bob), [theta], forcelist=loads, frame=N)
"""

_KANE = """
import sympy as sp
from sympy.physics.mechanics import KanesMethod, Particle, Point, ReferenceFrame, dynamicsymbols

theta, w, tau = dynamicsymbols("theta w tau")
m, l, b, g = sp.symbols("m l b g")
N = ReferenceFrame("N")
A = N.orientnew("A", "Axis", (theta, N.z))
A.set_ang_vel(N, w * N.z)
O = Point("O")
O.set_vel(N, 0)
P = O.locatenew("P", -l * A.y)
P.v2pt_theory(O, N, A)
METHOD = KanesMethod(N, q_ind=[theta], u_ind=[w], kd_eqs=[w - theta.diff()])
METHOD.kanes_equations([Particle("bob", P, m)], [(P, -m * g * N.y), (A, (tau - b * w) * N.z)])
"""

_PAIR = """
import sympy as sp
from sympy.physics.mechanics import dynamicsymbols

theta, tau = dynamicsymbols("theta tau")
m, l, b, g = sp.symbols("m l b g")
METHOD = (sp.Matrix([[m * l**2]]), sp.Matrix([tau - b * theta.diff() - m * g * l * sp.sin(theta)]))
"""

#: name → (suffix, model file, (old, new, check, entry)): a planted error, a check it fails and the
#: entry the diagnosis names (None where it names none: q̈ alone gives no M, C·q̇, H to compare)
FORMS = {
    "text, every key": (".toml", _text("""
M = [["m*l**2"]]
C = [["0"]]
H = ["m*g*l*sin(theta)"]
V = "-m*g*l*cos(theta)"
D = [["b"]]
B = [["1"]]
det_M = "m*l**2"
M_inv = [["1/(m*l**2)"]]
qddot = ["(tau - b*dtheta - m*g*l*sin(theta))/(m*l**2)"]
"""), ('M_inv = [["1/(m*l**2)"]]', 'M_inv = [["1/(m*l**3)"]]', "minverse", "Minv[1,1]")),
    "text, W": (".toml", _text("""
M = [["m*l**2"]]
C = [["0"]]
H = ["m*g*l*sin(theta)"]
D = [["b"]]
B = [["1"]]
W = [["l"]]
disturbances = ["w"]
"""), ('M = [["m*l**2"]]', 'M = [["m*l**2 + m"]]', "crba", "M[1,1]")),
    "text, Cqdot and V": (".toml", _text("""
M = [["m*l**2"]]
Cqdot = ["0"]
V = "-m*g*l*cos(theta)"
D = [["b"]]
B = [["1"]]
"""), ('V = "-m*g*l*cos(theta)"', 'V = "m*g*l*cos(theta)"', "gravity", "H[1]")),
    "text, C_plus_D": (".toml", _text("""
M = [["m*l**2"]]
C_plus_D = [["b"]]
H = ["m*g*l*sin(theta)"]
D = [["b"]]
B = [["1"]]
"""), ('C_plus_D = [["b"]]', 'C_plus_D = [["b + m*dtheta"]]', "coriolis", "C[1,1]")),
    "text, f": (".toml", _text("""
M = [["m*l**2"]]
f = ["tau - b*dtheta - m*g*l*sin(theta)"]
"""), ("m*g*l*sin(theta)", "m*g*sin(theta)", "gravity", "H[1]")),
    "text, whole equations": (".toml", _text("""
equations = ["m*l**2*ddtheta + b*dtheta + m*g*l*sin(theta) = tau"]
"""), ("m*l**2*ddtheta", "m*l*ddtheta", "crba", "M[1,1]")),
    "text, matrix equation": (".toml", _text("""
M = [["m*l**2"]]
D = [["b"]]
G = ["m*g*l*sin(theta)"]
B = [["1"]]
equations = ["M*ddq + D*dq + G = B*u"]
"""), ('G = ["m*g*l*sin(theta)"]', 'G = ["m*g*l*cos(theta)"]', "gravity", "G[1]")),
    "text, matrix equation with h": (".toml", _text("""
M = [["m*l**2"]]
h = ["b*dtheta + m*g*l*sin(theta)"]
equations = ["M*ddq + h = u"]
"""), ('M = [["m*l**2"]]', 'M = [["2*m*l**2"]]', "crba", "M[1,1]")),
    "text, qddot and B": (".toml", _text("""
qddot = ["(tau - b*dtheta - m*g*l*sin(theta))/(m*l**2)"]
B = [["1"]]
D = [["b"]]
"""), ("(m*l**2)", "(m*l)", "crba", "M[1,1]")),
    "text, qddot alone": (".toml", _text("""
qddot = ["(-b*dtheta - m*g*l*sin(theta))/(m*l**2)"]
D = [["b"]]
""", inputs=""), ("- m*g*l", "- 2*m*g*l", "aba", None)),
    "LaTeX, every key as a bmatrix": (".toml", _latex(r"""
M = '\begin{bmatrix} m l^2 \end{bmatrix}'
C = '\begin{bmatrix} 0 \end{bmatrix}'
H = '\begin{bmatrix} m g l \sin\theta \end{bmatrix}'
V = '-m g l \cos\theta'
D = '\begin{bmatrix} b \end{bmatrix}'
B = '\begin{bmatrix} 1 \end{bmatrix}'
det_M = 'm l^2'
M_inv = '\begin{bmatrix} \frac{1}{m l^2} \end{bmatrix}'
qddot = '\begin{bmatrix} \frac{\tau - b\dot\theta - m g l \sin\theta}{m l^2} \end{bmatrix}'
"""), (r"'\begin{bmatrix} m l^2 \end{bmatrix}'", r"'\begin{bmatrix} m l \end{bmatrix}'", "crba", "M[1,1]")),
    "LaTeX, each entry alone": (".toml", _latex(r"""
M = 'm l^2'
C = '0'
H = 'm g l \sin\theta'
D = 'b'
B = '1'
"""), (r"H = 'm g l \sin\theta'", r"H = 'm g \sin\theta'", "gravity", "H[1]")),
    "LaTeX, lists of entries": (".toml", _latex(r"""
M = [['m l^2']]
C = [['0']]
H = ['m g l \sin\theta']
D = [['b']]
B = [['1']]
"""), ("D = [['b']]", "D = [['2 b']]", "damping", "D[1,1]")),
    "LaTeX, C_plus_D": (".toml", _latex(r"""
M = 'm l^2'
C_plus_D = '\begin{bmatrix} b \end{bmatrix}'
H = 'm g l \sin\theta'
D = 'b'
B = '1'
"""), (r"{bmatrix} b \end", r"{bmatrix} b + m \dot\theta \end", "coriolis", "C[1,1]")),
    "LaTeX, f": (".toml", _latex(r"""
M = 'm l^2'
f = '\begin{bmatrix} \tau - b\dot\theta - m g l \sin\theta \end{bmatrix}'
"""), ("m g l", "m g", "gravity", "H[1]")),
    "LaTeX, whole equations": (".toml", _latex(r"""
equations = 'm l^2 \ddot\theta + b\dot\theta + m g l\sin\theta = \tau'
"""), (r"m l^2 \ddot", r"m l \ddot", "crba", "M[1,1]")),
    # planted: − G, so the hand's H is −G, no longer the file's G as it stands: named H (with + G, G)
    "LaTeX, matrix equation": (".toml", _latex(r"""
M = '\begin{bmatrix} m l^2 \end{bmatrix}'
D = '\begin{bmatrix} b \end{bmatrix}'
G = '\begin{bmatrix} m g l\sin\theta \end{bmatrix}'
B = '\begin{bmatrix} 1 \end{bmatrix}'
equations = ['M(q)\ddot{q} + D\dot{q} + G(q) = B\tau']
"""), ("+ G(q) = B", "- G(q) = B", "gravity", "H[1]")),
    "LaTeX, qddot and B": (".toml", _latex(r"""
qddot = '\frac{\tau - b\dot\theta - m g l \sin\theta}{m l^2}'
B = '1'
D = 'b'
"""), ("{m l^2}", "{m l}", "crba", "M[1,1]")),
    "mechanics, LagrangesMethod": (".py", _LAGRANGE + _MECHANICS_DECLARATION,
                                   ('Particle("bob", P, m)', 'Particle("bob", P, 2 * m)', "crba", "M[1,1]")),
    "mechanics, KanesMethod": (".py", _KANE + _MECHANICS_DECLARATION,
                               ("(P, -m * g * N.y)", "(P, -2 * m * g * N.y)", "gravity", "H[1]")),
    "mechanics, (M, forcing)": (".py", _PAIR + _MECHANICS_DECLARATION,
                                ("sp.Matrix([[m * l**2]])", "sp.Matrix([[m * l]])", "crba", "M[1,1]")),
    "DYNAMICS f(x, u)": (".py", _dynamics("""
def pendulum(x, u, *, m, l, b, g):
    theta, dtheta = x
    return [dtheta, (u[0] - b * dtheta - m * g * l * math.sin(theta)) / (m * l * l)]


DYNAMICS = pendulum
""", "f(x, u)"), ("m * g * l * math", "m * g * math", "gravity", None)),
    "DYNAMICS f(t, x, u)": (".py", _dynamics("""
def pendulum(t, x, u, *, m, l, b, g):
    theta, dtheta = x
    return [dtheta, (u[0] - b * dtheta - m * g * l * math.sin(theta)) / (m * l * l)]


DYNAMICS = pendulum
""", "f(t, x, u)"), ("/ (m * l * l)", "/ (m * l)", "crba", None)),
    "DYNAMICS qddot(q, v, u)": (".py", _dynamics("""
def pendulum(q, v, u, *, m, l, b, g):
    return [(u[0] - b * v[0] - m * g * l * math.sin(q[0])) / (m * l * l)]


DYNAMICS = pendulum
""", "qddot(q, v, u)"), ('"D": [["b"]]', '"D": [["2*b"]]', "damping", None)),
    "DYNAMICS qddot(q, v, u) without inputs": (".py", _dynamics("""
def pendulum(q, v, u, *, m, l, b, g):
    return [(-b * v[0] - m * g * l * math.sin(q[0])) / (m * l * l)]


DYNAMICS = pendulum
""", "qddot(q, v, u)", inputs=False), ("-b * v[0]", "b * v[0]", "aba", None)),
}  # fmt: skip

CART = """name = "cart"
inputs = ["F"]
M = [["m"]]
C = [["0"]]
H = ["4*m*g/5"]
D = [["b"]]
B = [["1"]]

[coordinates]
x = "position"

[parameters]
m = { kind = "mass", unit = "kg" }
b = { kind = "damping", unit = "N·s/m" }
g = { kind = "gravity", unit = "m/s²" }

[urdf]
joints = ["slider"]
"""
