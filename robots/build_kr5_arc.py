"""Writes robots/kr5_arc.urdf and robots/kr5_arc.limits.yaml from the figures below.

    .venv/bin/python robots/build_kr5_arc.py           # rewrite both files after editing this script
    .venv/bin/python robots/build_kr5_arc.py --check   # exit 1 if the files differ from what it writes

KUKA KR 5 arc, frames per REP-103 and the ROS-Industrial conventions (docs/reference.md section 3):

* ``base_link`` on the mounting face, z up, x forward; ``base`` = KUKA $ROBROOT (coincides with base_link).
* Joint values equal the controller's A1..A6. At all zeros the arm is stretched horizontally along +x
  (upper arm and forearm along x); A1, A4 and A6 turn about -z/-x because KUKA counts them clockwise.
* The KUKA home pose A = (0, -90, 90, 0, 0, 0) deg has the upper arm vertical and the forearm horizontal;
  it is the OPW zero pose with the forearm lowered by 90 deg.
* ``tool0`` = $FLANGE: origin on the flange face, x out of the flange (KUKA's tool direction), no rotation
  w.r.t. link_6.

Kinematics, OPW parameters of ros-industrial/kuka_experimental (kuka_kr5_support) [m]: a1 = 0.180,
a2 = -0.120, b = 0, c1 = 0.400, c2 = 0.600, c3 = 0.620, c4 = 0.115. The URDF places A2 at (a1, 0, c1),
A3 c2 further along the upper arm, A4 -a2 above the A3 axis, A5 c3 along the forearm and the flange c4
beyond A5; tests/test_ik.py checks the forward kinematics against the OPW closed form.

Geometry (docs/reference.md section 3): ``ENVELOPE`` is the real arm's outline, per link a few boxes and
cylinders (lengths from the kinematics above, widths and heights the cell's estimates of the data sheet's
dimension drawing, on the generous side), the dress pack (hose package) along the upper arm and the forearm,
and a typical 22 deg-neck MAG torch to size. The visual shapes are the envelope; the collision shapes are the
envelope grown by ``ARM_MARGIN`` on every side (the torch, whose nozzle must reach into the fillet, by
``TORCH_MARGIN``), so they enclose the real arm (tests/unit/test_arm_envelope.py). Masses are rough estimates
(the data sheet gives 127 kg in total) for the simulator only; inertias follow from the primitives.
"""

from __future__ import annotations

import math
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
URDF_PATH = HERE / "kr5_arc.urdf"
LIMITS_PATH = HERE / "kr5_arc.limits.yaml"

# OPW parameters [m] (ros-industrial/kuka_experimental, kuka_kr5_support).
A1, A2, B, C1, C2, C3, C4 = 0.180, -0.120, 0.0, 0.400, 0.600, 0.620, 0.115

# (name, parent, child, origin xyz [m], axis, lower [deg], upper [deg], max speed [deg/s], effort [N m]).
# Ranges and speeds: KUKA KR 5 arc data sheet (docs/reference.md section 3). Effort: not published; rough
# estimates of the holding torque with 5 kg payload, used only by a simulator's motor model.
JOINTS = (
    ("joint_a1", "base_link", "link_1", (0.0, 0.0, C1), (0, 0, -1), -155.0, 155.0, 154.0, 300.0),
    ("joint_a2", "link_1", "link_2", (A1, B, 0.0), (0, 1, 0), -180.0, 65.0, 154.0, 400.0),
    ("joint_a3", "link_2", "link_3", (C2, 0.0, 0.0), (0, 1, 0), -15.0, 158.0, 228.0, 200.0),
    ("joint_a4", "link_3", "link_4", (0.0, 0.0, -A2), (-1, 0, 0), -350.0, 350.0, 343.0, 40.0),
    ("joint_a5", "link_4", "link_5", (C3, 0.0, 0.0), (0, 1, 0), -130.0, 130.0, 384.0, 40.0),
    ("joint_a6", "link_5", "link_6", (C4, 0.0, 0.0), (-1, 0, 0), -350.0, 350.0, 721.0, 20.0),
)

# Acceleration and jerk are not published by KUKA. Assumed: a_max = 2.5 * v_max [1/s] (full speed after
# 0.4 s) and j_max = 10 * a_max [1/s] (full acceleration after 0.1 s), usual figures for industrial arms.
ACCEL_PER_SPEED = 2.5  # [1/s]
JERK_PER_ACCEL = 10.0  # [1/s]

# Torch: a straight body along the flange x axis, then neck and wire bent by NECK_BEND towards -z of tool0.
# A typical 22 deg-neck MAG torch for a 5 kg arm: a shock sensor (collision breaker) and clamp of about 70 mm
# diameter on the flange, a 44 mm body, a 32 mm neck tube, a 25 mm gas nozzle.
TORCH_BODY = 0.250  # flange to the bend [m]
NECK_BEND = math.radians(22.0)  # [rad]
NECK, NOZZLE, STICKOUT = 0.085, 0.030, 0.015  # bend to nozzle, nozzle length, contact tip to wire tip [m]
SENSOR_LENGTH, SENSOR_RADIUS = 0.090, 0.035  # shock sensor and clamp on the flange [m]
BODY_RADIUS, NECK_RADIUS, NOZZLE_RADIUS = 0.022, 0.016, 0.0125  # [m]
# Eye-in-hand depth camera (RealSense D415 outline) above the torch body, pitched down to the wire tip.
CAMERA_XYZ = (0.100, 0.0, 0.080)  # [m] in tool0
CAMERA_PITCH = math.radians(25.0)  # [rad] about tool0 y: x (the viewing direction) tilted towards the torch tip
ARM_MARGIN = 0.010  # [m] the arm's collision shapes: its envelope grown by this on every side
TORCH_MARGIN = 0.0  # [m] the torch's: modelled to size (its nozzle reaches a few mm from both faces of a fillet)


@dataclass(frozen=True)
class Shape:
    """A box (size x, y, z) or cylinder (radius, length along its z) in a link frame."""

    kind: str
    dims: tuple[float, ...]
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def grown(self, margin: float) -> Shape:
        """The same shape ``margin`` [m] larger on every side."""
        if self.kind == "box":
            return Shape("box", tuple(d + 2.0 * margin for d in self.dims), self.xyz, self.rpy)
        r, h = self.dims
        return Shape("cylinder", (r + margin, h + 2.0 * margin), self.xyz, self.rpy)


def _along_x(r: float, x0: float, x1: float, y: float = 0.0, z: float = 0.0) -> Shape:
    return Shape("cylinder", (r, x1 - x0), ((x0 + x1) / 2.0, y, z), (0.0, math.pi / 2.0, 0.0))


def _along_y(r: float, length: float, x: float = 0.0) -> Shape:
    return Shape("cylinder", (r, length), (x, 0.0, 0.0), (math.pi / 2.0, 0.0, 0.0))


def _box(lo: tuple[float, float, float], hi: tuple[float, float, float]) -> Shape:
    """The box between corners lo and hi [m]."""
    size = tuple(b - a for a, b in zip(lo, hi, strict=True))
    centre = tuple((a + b) / 2.0 for a, b in zip(lo, hi, strict=True))
    return Shape("box", size, centre)  # type: ignore[arg-type]


def _torch_shapes() -> tuple[Shape, ...]:
    d = np.array([math.cos(NECK_BEND), 0.0, -math.sin(NECK_BEND)])  # wire direction in tool0
    pitch = math.pi / 2.0 + NECK_BEND  # Ry(pitch) maps z onto d
    bend = np.array([TORCH_BODY, 0.0, 0.0])
    neck_c = bend + d * NECK / 2.0
    nozzle_c = bend + d * (NECK + NOZZLE / 2.0)
    return (
        _along_x(SENSOR_RADIUS, 0.0, SENSOR_LENGTH),  # clamp and shock sensor on the flange
        _along_x(BODY_RADIUS, SENSOR_LENGTH, TORCH_BODY + BODY_RADIUS * math.tan(NECK_BEND / 2.0)),  # body
        Shape("box", (0.020, 0.030, 0.040), (CAMERA_XYZ[0], 0.0, 0.042)),  # camera bracket
        Shape("cylinder", (NECK_RADIUS, NECK), tuple(neck_c), (0.0, pitch, 0.0)),  # bent neck
        Shape("cylinder", (NOZZLE_RADIUS, NOZZLE), tuple(nozzle_c), (0.0, pitch, 0.0)),  # gas nozzle
    )


def torch_tcp_xyz_rpy() -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Wire tip in tool0 [m] and its rpy [rad]: z along the wire, out of the torch; y = tool0 y."""
    d = np.array([math.cos(NECK_BEND), 0.0, -math.sin(NECK_BEND)])
    tip = np.array([TORCH_BODY, 0.0, 0.0]) + d * (NECK + NOZZLE + STICKOUT)
    return tuple(tip), (0.0, math.pi / 2.0 + NECK_BEND, 0.0)


# The real arm's outline per link [m], in the link frames at zero joints (arm stretched along +x; see the module
# docstring); docs/reference.md section 3 gives the figures. Lengths follow the kinematics; widths and heights
# are estimates of the dimension drawing, rounded up.
ENVELOPE: dict[str, tuple[Shape, ...]] = {
    "base_link": (_box((-0.17, -0.17, 0.0), (0.17, 0.17, 0.22)),),  # foot and A1 gear, 340 x 340 x 220
    "link_1": (  # frame at A2's height (400 mm above the mounting face), A2 180 mm ahead
        Shape("cylinder", (0.165, 0.18), (0.0, 0.0, -0.11)),  # carousel, 330 mm across, down to the base
        _box((-0.10, -0.15, -0.13), (0.30, 0.15, 0.13)),  # shoulder and the A2 gear, 300 mm wide
        _box((-0.24, -0.09, -0.15), (-0.08, 0.09, 0.10)),  # A1 and A2 motors behind the axis
    ),
    "link_2": (  # upper arm, A2 to A3 (600 mm)
        _along_y(0.12, 0.22),  # A2 hub, 240 mm across
        _box((0.0, -0.085, -0.075), (0.60, 0.085, 0.075)),  # arm 170 x 150 mm
        _along_y(0.10, 0.20, x=0.60),  # A3 hub
        _along_x(0.035, 0.05, 0.55, z=0.13),  # dress pack (hose package) along the upper arm's back, 70 mm
    ),
    "link_3": (  # elbow: A3 hub, the A4 to A6 motors behind it, the forearm's root; A4 axis 120 mm above A3
        _box((-0.18, -0.10, -0.11), (0.14, 0.10, 0.21)),
        _along_x(0.035, -0.15, 0.10, z=0.245),  # the dress pack over the elbow
    ),
    "link_4": (  # forearm about A4, to A5 (620 mm)
        _along_x(0.07, 0.15, 0.56),  # tube, 140 mm across (its root inside the elbow housing)
        _along_x(0.03, 0.15, 0.50, z=0.10),  # the hose package's sleeve on the forearm
    ),
    "link_5": (_along_y(0.06, 0.14), _box((0.0, -0.05, -0.05), (0.10, 0.05, 0.05))),  # wrist: A5 hub, A6 gear
    "link_6": (_along_x(0.04, -0.015, 0.0),),  # flange disk behind the flange face
    "torch": _torch_shapes(),
    "camera_link": (Shape("box", (0.023, 0.099, 0.020)),),
}
LINK_MARGIN = {name: (TORCH_MARGIN if name in ("torch", "camera_link") else ARM_MARGIN) for name in ENVELOPE}

# (link, mass [kg], colour). Link frames: see the module docstring (arm drawn at zero joints).
MASSES: tuple[tuple[str, float, str], ...] = (
    ("base_link", 35.0, "grey"),
    ("link_1", 30.0, "orange"),
    ("link_2", 18.0, "orange"),
    ("link_3", 14.0, "orange"),
    ("link_4", 6.0, "orange"),
    ("link_5", 2.5, "orange"),
    ("link_6", 0.4, "grey"),
    ("torch", 1.8, "dark"),
    ("camera_link", 0.1, "black"),
)
# Links that are frames only; they get a negligible inertia so that simulators do not invent one (PyBullet
# assumes 1 kg for a link without <inertial>).
FRAME_LINKS = ("base", "tool0", "torch_tcp", "camera_optical")

COLOURS = {
    "orange": "1.0 0.4 0.0 1.0",  # KUKA orange
    "grey": "0.35 0.35 0.35 1.0",
    "dark": "0.15 0.15 0.15 1.0",
    "black": "0.02 0.02 0.02 1.0",
}


def _rpy_matrix(rpy: tuple[float, ...]) -> np.ndarray:
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    Rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    Ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    Rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def _volume_and_inertia(s: Shape) -> tuple[float, np.ndarray]:
    """Volume [m^3] and inertia per unit mass about the shape's centre, in the shape's own axes [m^2]."""
    if s.kind == "box":
        x, y, z = s.dims
        return x * y * z, np.diag([y * y + z * z, x * x + z * z, x * x + y * y]) / 12.0
    r, h = s.dims
    t = (3.0 * r * r + h * h) / 12.0
    return math.pi * r * r * h, np.diag([t, t, r * r / 2.0])


def _inertial(mass: float, shapes: tuple[Shape, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Centre of mass (3,) [m] and inertia (3, 3) [kg m^2] about it, mass spread over the shapes by volume."""
    vols = [_volume_and_inertia(s)[0] for s in shapes]
    masses = mass * np.array(vols) / sum(vols)
    centres = np.array([s.xyz for s in shapes])
    com = masses @ centres / mass
    inertia = np.zeros((3, 3))
    for m, s in zip(masses, shapes, strict=True):
        R = _rpy_matrix(s.rpy)
        d = np.array(s.xyz) - com
        inertia += m * (R @ _volume_and_inertia(s)[1] @ R.T) + m * (d @ d * np.eye(3) - np.outer(d, d))
    return com, inertia


def _num(v: float) -> str:
    s = f"{v:.12g}"
    return "0" if s == "-0" else s


def _vec(v: tuple[float, ...] | np.ndarray) -> str:
    return " ".join(_num(float(x)) for x in v)


def _origin(parent: ET.Element, xyz: tuple[float, ...], rpy: tuple[float, ...] = (0.0, 0.0, 0.0)) -> None:
    ET.SubElement(parent, "origin", xyz=_vec(xyz), rpy=_vec(rpy))


def _geometry(parent: ET.Element, s: Shape) -> None:
    g = ET.SubElement(parent, "geometry")
    if s.kind == "box":
        ET.SubElement(g, "box", size=_vec(s.dims))
    else:
        ET.SubElement(g, "cylinder", radius=_num(s.dims[0]), length=_num(s.dims[1]))


def _link(
    robot: ET.Element,
    name: str,
    mass: float,
    colour: str | None,
    shapes: tuple[Shape, ...],
    margin: float = 0.0,
) -> None:
    """A link whose visual shapes are ``shapes`` and whose collision shapes are those grown by ``margin`` [m]."""
    link = ET.SubElement(robot, "link", name=name)
    inertial = ET.SubElement(link, "inertial")
    if shapes:
        com, inertia = _inertial(mass, shapes)
    else:
        com, inertia = np.zeros(3), np.eye(3) * 1e-6
    _origin(inertial, tuple(com))
    ET.SubElement(inertial, "mass", value=_num(mass))
    names = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
    idx = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))
    ET.SubElement(inertial, "inertia", {k: _num(float(inertia[i])) for k, i in zip(names, idx, strict=True)})
    for tag in ("visual", "collision"):
        for s in shapes:
            g = s.grown(margin) if tag == "collision" else s
            el = ET.SubElement(link, tag)
            _origin(el, g.xyz, g.rpy)
            _geometry(el, g)
            if tag == "visual" and colour is not None:
                ET.SubElement(el, "material", name=colour)


def _fixed(robot: ET.Element, parent: str, child: str, xyz: tuple[float, ...], rpy: tuple[float, ...]) -> None:
    j = ET.SubElement(robot, "joint", name=f"{parent}-{child}", type="fixed")
    _origin(j, xyz, rpy)
    ET.SubElement(j, "parent", link=parent)
    ET.SubElement(j, "child", link=child)


def build_urdf() -> str:
    """The URDF text."""
    robot = ET.Element("robot", name="kuka_kr5_arc")
    robot.append(ET.Comment(" Generated by robots/build_kr5_arc.py: edit that script, not this file. "))
    for name, rgba in COLOURS.items():
        ET.SubElement(ET.SubElement(robot, "material", name=name), "color", rgba=rgba)
    for name, mass, colour in MASSES:
        _link(robot, name, mass, colour, ENVELOPE[name], LINK_MARGIN[name])
    for name in FRAME_LINKS:
        _link(robot, name, 0.001, None, ())
    _fixed(robot, "base_link", "base", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))  # $ROBROOT
    for name, parent, child, xyz, axis, lo, hi, vel, effort in JOINTS:
        j = ET.SubElement(robot, "joint", name=name, type="revolute")
        _origin(j, xyz)
        ET.SubElement(j, "parent", link=parent)
        ET.SubElement(j, "child", link=child)
        ET.SubElement(j, "axis", xyz=_vec(axis))
        ET.SubElement(
            j,
            "limit",
            lower=_num(math.radians(lo)),
            upper=_num(math.radians(hi)),
            velocity=_num(math.radians(vel)),
            effort=_num(effort),
        )
    _fixed(robot, "link_6", "tool0", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))  # $FLANGE
    _fixed(robot, "tool0", "torch", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    _fixed(robot, "torch", "torch_tcp", *torch_tcp_xyz_rpy())
    _fixed(robot, "torch", "camera_link", CAMERA_XYZ, (0.0, CAMERA_PITCH, 0.0))
    # REP-103 optical frame: z forward (= camera_link x), x right (= -y), y down (= -z).
    _fixed(robot, "camera_link", "camera_optical", (0.0, 0.0, 0.0), (-math.pi / 2.0, 0.0, -math.pi / 2.0))
    ET.indent(robot, space="  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding="unicode") + "\n"


def build_limits_yaml() -> str:
    """The per-joint velocity, acceleration and jerk limits, with their sources, as YAML text."""
    lines = [
        "# KUKA KR 5 arc joint motion limits for trajectory timing (Ruckig), SI units.",
        "# Generated by robots/build_kr5_arc.py: edit that script, not this file.",
        "# velocity [rad/s]: KUKA KR 5 arc data sheet, max axis speeds 154, 154, 228, 343, 384, 721 deg/s",
        "#   (docs/reference.md section 3); the URDF <limit velocity> holds the same values.",
        f"# acceleration [rad/s^2]: not published by KUKA; assumed {ACCEL_PER_SPEED:g} x velocity"
        " (full speed reached in 0.4 s).",
        f"# jerk [rad/s^3]: not published; assumed {JERK_PER_ACCEL:g} x acceleration (full acceleration in 0.1 s).",
        "# Values may be lowered here (a slower cell); raising velocity above the URDF's is an error.",
        "joints:",
    ]
    for name, *_rest, vel, _effort in JOINTS:
        v = math.radians(vel)
        a = ACCEL_PER_SPEED * v
        j = JERK_PER_ACCEL * a
        lines.append(f"  {name}: {{velocity: {_num(v)}, acceleration: {_num(a)}, jerk: {_num(j)}}}  # {vel:g} deg/s")
    return "\n".join(lines) + "\n"


def main(argv: list[str]) -> int:
    outputs = {URDF_PATH: build_urdf(), LIMITS_PATH: build_limits_yaml()}
    if "--check" in argv:
        stale = [p.name for p, text in outputs.items() if not p.exists() or p.read_text() != text]
        if stale:
            print(f"out of date: {', '.join(stale)}; run python robots/build_kr5_arc.py")
            return 1
        return 0
    for path, text in outputs.items():
        path.write_text(text)
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
