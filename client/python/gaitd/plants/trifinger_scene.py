"""TriFingerPro in MuJoCo: the hand description read from its URDF and gaitd section, and the MJCF built from it.

Standard library only (``xml.etree``, ``tomllib``): the description is read
from the files gaitd ships (``deploy/hands/trifingerpro/``: the URDF with
upstream's numbers and ``hand.toml``), never from copies of their numbers.

The scene (``build_xml``):

* **The fingers, link by link from the URDF.** Every URDF link below the
  hand frame becomes a body placed at its joint's origin (xyz, rpy); a
  revolute joint becomes a hinge about the URDF axis at the body origin; a
  fixed joint nests the body without a joint. The hinges have no stops: the
  URDF's limits are the robot's *soft* limits, which its action law
  enforces (``trifinger_hand``), and the mechanical stops lie beyond the
  driver's wider hard limits, which the URDF does not give. Each link's
  mass, centre of mass and full inertia tensor are the URDF's (rotated by
  the inertial origin's rpy). Collision primitives are the URDF's: a sphere
  stays a sphere (the 10 mm tip at the tip frame), a cylinder becomes the
  capsule of the same axis, radius and half-length, which encloses it (as
  the planner's link capsules do).
* **Torque motors** on every revolute joint, clamped at ± the URDF's
  ``effort`` (TriFingerPro: 0.396 N·m). The plant computes the motor torque
  with the robot's action law (``trifinger_hand``); the clamp is a second
  guard, never the one that acts.
* **The object**: a free sphere of ``hand.toml``'s radius and mass at its
  centre; a tennis ball is hollow, so its inertia is a thin shell's,
  ⅔ m R² (``object_inertia_factor``).
* **Gravity** from ``hand.toml``, on.
* **Contacts** are explicit pairs only (every geom has contype = conaffinity
  = 0): the object with each tip sphere — the soft finger of
  ``tests/oracles/mujoco/NOTES.md``: condim 4 (normal, two tangential, torsion),
  friction (μ, μ, torsion), elliptic cones, impratio 10, noslip iterations,
  solref time constant 2 × timestep and a flat solimp (a linear contact
  spring) — the object with every link capsule (condim 3, μ: links should
  never touch it, and if they do, they push), and the object with a floor
  plane at z = 0 of the hand frame (the arena).
* **Timestep 1 ms** by default: the robot's own control period (robot_fingers
  applies one action per millisecond and holds it), so one physics step is
  one action of the real robot, and the contact time constant of 2 ms that
  NOTES.md found stiff enough against creep is 2 × timestep. A finer step
  (``timestep``) keeps the 2 × timestep contact and runs the action law
  every step.
"""

from __future__ import annotations

import math
import tomllib
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

Vec3 = tuple[float, float, float]
Mat3 = tuple[Vec3, Vec3, Vec3]

#: The TriFingerPro description shipped with gaitd, where a checkout has it.
DEFAULT_HAND_DIR = Path(__file__).resolve().parents[4] / "deploy" / "hands" / "trifingerpro"


@dataclass(frozen=True)
class Origin:
    """A URDF ``<origin>``: translation [m] and roll-pitch-yaw [rad] (fixed axes x, y, z)."""

    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Inertial:
    """A link's mass [kg], centre of mass and inertia about it [kg·m²] (ixx, iyy, izz, ixy, ixz, iyz)."""

    origin: Origin
    mass: float
    inertia: tuple[float, float, float, float, float, float]


@dataclass(frozen=True)
class Collision:
    """A collision primitive: ``sphere`` (radius) or ``cylinder`` (radius, length along its local z)."""

    origin: Origin
    kind: str
    radius: float
    length: float = 0.0


@dataclass(frozen=True)
class Link:
    """A URDF link."""

    name: str
    inertial: Inertial | None
    collisions: tuple[Collision, ...]


@dataclass(frozen=True)
class Joint:
    """A URDF joint: ``revolute`` or ``fixed`` (limits and effort only for revolute)."""

    name: str
    kind: str
    parent: str
    child: str
    origin: Origin
    axis: Vec3
    lower: float
    upper: float
    effort: float
    velocity: float


@dataclass(frozen=True)
class Urdf:
    """The links and joints of a URDF."""

    name: str
    links: dict[str, Link]
    joints: tuple[Joint, ...]

    def children(self, link: str) -> list[Joint]:
        """The joints whose parent is ``link``, in file order."""
        return [j for j in self.joints if j.parent == link]

    def chain(self, base: str, tip: str) -> list[Joint]:
        """The joints from ``base`` down to ``tip`` (fixed ones included), in order."""
        by_child = {j.child: j for j in self.joints}
        out: list[Joint] = []
        link = tip
        while link != base:
            if link not in by_child:
                raise ValueError(f"{tip} is not below {base}")
            j = by_child[link]
            out.append(j)
            link = j.parent
        return out[::-1]


def _floats(text: str | None, n: int, default: float = 0.0) -> tuple[float, ...]:
    if text is None:
        return (default,) * n
    v = tuple(float(s) for s in text.split())
    if len(v) != n:
        raise ValueError(f"expected {n} numbers, got {text!r}")
    return v


def _origin(el: ET.Element | None) -> Origin:
    if el is None:
        return Origin()
    xyz = _floats(el.get("xyz"), 3)
    rpy = _floats(el.get("rpy"), 3)
    return Origin((xyz[0], xyz[1], xyz[2]), (rpy[0], rpy[1], rpy[2]))


def parse_urdf(text: str) -> Urdf:
    """The links and joints of a URDF document (revolute and fixed joints; spheres and cylinders)."""
    root = ET.fromstring(text)
    links: dict[str, Link] = {}
    for el in root.findall("link"):
        inertial = None
        ie = el.find("inertial")
        if ie is not None:
            mass_el, inertia_el = ie.find("mass"), ie.find("inertia")
            if mass_el is None or inertia_el is None:
                raise ValueError(f"link {el.get('name')}: inertial needs mass and inertia")
            ixx, iyy, izz, ixy, ixz, iyz = (
                float(inertia_el.get(k, "0")) for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
            )
            inertia = (ixx, iyy, izz, ixy, ixz, iyz)
            inertial = Inertial(_origin(ie.find("origin")), float(mass_el.get("value", "nan")), inertia)
        cols: list[Collision] = []
        for ce in el.findall("collision"):
            geom = ce.find("geometry")
            shape = None if geom is None else next(iter(geom), None)
            if shape is None:
                raise ValueError(f"link {el.get('name')}: collision without geometry")
            if shape.tag == "sphere":
                cols.append(Collision(_origin(ce.find("origin")), "sphere", float(shape.get("radius", "nan"))))
            elif shape.tag == "cylinder":
                cols.append(
                    Collision(
                        _origin(ce.find("origin")),
                        "cylinder",
                        float(shape.get("radius", "nan")),
                        float(shape.get("length", "nan")),
                    )
                )
            else:
                raise ValueError(f"link {el.get('name')}: collision {shape.tag} not supported (sphere, cylinder)")
        name = el.get("name", "")
        links[name] = Link(name, inertial, tuple(cols))
    joints: list[Joint] = []
    for el in root.findall("joint"):
        kind = el.get("type", "")
        if kind not in ("revolute", "fixed"):
            raise ValueError(f"joint {el.get('name')}: type {kind} not supported (revolute, fixed)")
        parent, child = el.find("parent"), el.find("child")
        if parent is None or child is None:
            raise ValueError(f"joint {el.get('name')}: needs parent and child")
        axis_el = el.find("axis")
        axis = _floats(axis_el.get("xyz"), 3) if axis_el is not None else (1.0, 0.0, 0.0)
        lim = el.find("limit")
        lower = upper = effort = velocity = math.nan
        if kind == "revolute":
            if lim is None:
                raise ValueError(f"joint {el.get('name')}: a revolute joint needs <limit>")
            lower, upper = float(lim.get("lower", "nan")), float(lim.get("upper", "nan"))
            effort, velocity = float(lim.get("effort", "nan")), float(lim.get("velocity", "nan"))
        joints.append(
            Joint(
                el.get("name", ""),
                kind,
                parent.get("link", ""),
                child.get("link", ""),
                _origin(el.find("origin")),
                (axis[0], axis[1], axis[2]),
                lower,
                upper,
                effort,
                velocity,
            )
        )
    return Urdf(root.get("name", ""), links, tuple(joints))


@dataclass(frozen=True)
class FingerSpec:
    """One finger of ``hand.toml``: its base and tip links and its revolute joints, base to tip."""

    name: str
    base: str
    tip: str
    joints: tuple[Joint, ...]
    tip_radius: float


@dataclass(frozen=True)
class HandSpec:
    """The hand as the URDF and ``hand.toml`` describe it (SI units)."""

    urdf: Urdf
    frame: str
    fingers: tuple[FingerSpec, ...]
    object_radius: float
    object_mass: float
    object_centre: Vec3
    mu: float
    torsion: float
    gravity: Vec3

    @property
    def joints(self) -> tuple[Joint, ...]:
        """Every finger's revolute joints, finger by finger."""
        return tuple(j for f in self.fingers for j in f.joints)


def load_hand(directory: Path = DEFAULT_HAND_DIR, section: str = "hand.toml") -> HandSpec:
    """Reads ``section`` (the gaitd hand section) in ``directory`` and the URDF it names."""
    cfg = tomllib.loads((directory / section).read_text(encoding="utf-8"))
    urdf = parse_urdf((directory / cfg["urdf"]).read_text(encoding="utf-8"))
    fingers = []
    for f in cfg["finger"]:
        chain = urdf.chain(f["base"], f["tip"])
        tip = urdf.links[f["tip"]]
        spheres = [c for c in tip.collisions if c.kind == "sphere" and c.origin == Origin()]
        if "tip_radius" in f:
            r = float(f["tip_radius"])
        elif spheres:
            r = spheres[0].radius
        else:
            raise ValueError(f"finger {f['name']}: no tip sphere at the tip frame and no tip_radius")
        fingers.append(FingerSpec(f["name"], f["base"], f["tip"], tuple(j for j in chain if j.kind == "revolute"), r))
    obj, fr = cfg["object"], cfg["friction"]
    c, g = obj["centre"], cfg.get("gravity", [0.0, 0.0, -9.81])
    return HandSpec(
        urdf=urdf,
        frame=cfg.get("frame", "base_link"),
        fingers=tuple(fingers),
        object_radius=float(obj["radius"]),
        object_mass=float(obj["mass"]),
        object_centre=(float(c[0]), float(c[1]), float(c[2])),
        mu=float(fr["mu"]),
        torsion=float(fr["torsion"]),
        gravity=(float(g[0]), float(g[1]), float(g[2])),
    )


# ---------------------------------------------------------------- rotations


def rpy_matrix(rpy: Vec3) -> Mat3:
    """URDF roll-pitch-yaw: R = Rz(yaw) · Ry(pitch) · Rx(roll)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return (
        (cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
        (sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
        (-sp, cp * sr, cp * cr),
    )


def rpy_quat(rpy: Vec3) -> tuple[float, float, float, float]:
    """The unit quaternion (w, x, y, z) of URDF roll-pitch-yaw."""
    r, p, y = (0.5 * a for a in rpy)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return (
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    )


def _rotate_inertia(i6: tuple[float, float, float, float, float, float], rpy: Vec3) -> tuple[float, ...]:
    ixx, iyy, izz, ixy, ixz, iyz = i6
    m = ((ixx, ixy, ixz), (ixy, iyy, iyz), (ixz, iyz, izz))
    r = rpy_matrix(rpy)
    out = [[sum(r[a][k] * m[k][n] * r[b][n] for k in range(3) for n in range(3)) for b in range(3)] for a in range(3)]
    return (out[0][0], out[1][1], out[2][2], out[0][1], out[0][2], out[1][2])


# ---------------------------------------------------------------- the scene


@dataclass(frozen=True)
class SceneOptions:
    """The simulation's own numbers (the hand's come from its description)."""

    timestep: float = 0.001
    contact_imp: float = 0.95
    impratio: float = 10.0
    noslip_iterations: int = 20
    tip_condim: int = 4
    object_inertia_factor: float = 2.0 / 3.0  # hollow ball (thin shell); a solid one is 0.4
    floor: bool = True

    @property
    def contact_timeconst(self) -> float:
        """solref time constant: 2 × timestep (NOTES.md: the stiffest that integrates stably, the least creep)."""
        return 2.0 * self.timestep


def _g(x: float) -> str:
    return f"{x:.12g}"


def _v(v: tuple[float, ...]) -> str:
    return " ".join(_g(x) for x in v)


def geom_name(link: str, index: int) -> str:
    """The MJCF name of the ``index``-th collision primitive of ``link``."""
    return f"{link}/{index}"


def build_xml(hand: HandSpec, opts: SceneOptions = SceneOptions()) -> str:
    """The MJCF text of the hand, the object and the floor (see the module docs)."""
    urdf = hand.urdf
    finger_links: set[str] = set()
    for f in hand.fingers:
        finger_links.update(j.child for j in urdf.chain(f.base, f.tip))
    tips = {f.tip for f in hand.fingers}

    def body(joint: Joint, depth: int) -> list[str]:
        pad = "  " * depth
        link = urdf.links[joint.child]
        o = joint.origin
        lines = [f'{pad}<body name="{link.name}" pos="{_v(o.xyz)}" quat="{_v(rpy_quat(o.rpy))}">']
        if joint.kind == "revolute":
            lines.append(f'{pad}  <joint name="{joint.name}" type="hinge" axis="{_v(joint.axis)}" limited="false"/>')
        if link.inertial is not None:
            ine = link.inertial
            full = _rotate_inertia(ine.inertia, ine.origin.rpy)
            lines.append(
                f'{pad}  <inertial pos="{_v(ine.origin.xyz)}" mass="{_g(ine.mass)}" fullinertia="{_v(full)}"/>'
            )
        for i, c in enumerate(link.collisions):
            name = geom_name(link.name, i)
            pose = f'pos="{_v(c.origin.xyz)}" quat="{_v(rpy_quat(c.origin.rpy))}"'
            if c.kind == "sphere":
                shape = f'type="sphere" size="{_g(c.radius)}"'
            else:  # the capsule that encloses the cylinder
                shape = f'type="capsule" size="{_g(c.radius)} {_g(0.5 * c.length)}"'
            lines.append(f'{pad}  <geom name="{name}" {shape} {pose} contype="0" conaffinity="0"/>')
        for child in urdf.children(link.name):
            lines += body(child, depth + 1)
        lines.append(f"{pad}</body>")
        return lines

    bodies: list[str] = []
    for j in urdf.children(hand.frame):
        bodies += body(j, 2)

    tc, imp = opts.contact_timeconst, opts.contact_imp
    solimp = f'solimp="{_g(imp)} {_g(imp)} 0.001 0.5 2"'
    solref = f'solref="{_g(tc)} 1"'
    pairs: list[str] = []
    for name in sorted(finger_links):
        for i, c in enumerate(urdf.links[name].collisions):
            g = geom_name(name, i)
            if name in tips and c.kind == "sphere":
                pairs.append(
                    f'    <pair name="object-{g}" geom1="object" geom2="{g}" condim="{opts.tip_condim}" '
                    f'friction="{_g(hand.mu)} {_g(hand.mu)} {_g(hand.torsion)} 0 0" {solref} {solimp} '
                    f'margin="0" gap="0"/>'
                )
            else:
                pairs.append(
                    f'    <pair name="object-{g}" geom1="object" geom2="{g}" condim="3" '
                    f'friction="{_g(hand.mu)} {_g(hand.mu)} 0 0 0" {solref} {solimp}/>'
                )
    if opts.floor:
        pairs.append(
            f'    <pair name="object-floor" geom1="object" geom2="floor" condim="3" '
            f'friction="{_g(hand.mu)} {_g(hand.mu)} 0 0 0" {solref} {solimp}/>'
        )
    motors = [
        f'    <motor name="{j.name}" joint="{j.name}" gear="1" ctrlrange="{_g(-j.effort)} {_g(j.effort)}" '
        f'ctrllimited="true"/>'
        for j in hand.joints
    ]
    R, m = hand.object_radius, hand.object_mass
    i_obj = opts.object_inertia_factor * m * R * R
    floor = (
        '    <geom name="floor" type="plane" size="0.3 0.3 0.01" contype="0" conaffinity="0"/>\n' if opts.floor else ""
    )
    nl = "\n"
    return f"""<mujoco model="{urdf.name}">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{_g(opts.timestep)}" gravity="{_v(hand.gravity)}" cone="elliptic" impratio="{_g(opts.impratio)}"
          solver="Newton" iterations="200" tolerance="1e-10" ls_iterations="50"
          noslip_iterations="{opts.noslip_iterations}" integrator="Euler"/>
  <worldbody>
{floor}    <body name="object" pos="{_v(hand.object_centre)}">
      <freejoint name="object"/>
      <inertial pos="0 0 0" mass="{_g(m)}" diaginertia="{_g(i_obj)} {_g(i_obj)} {_g(i_obj)}"/>
      <geom name="object" type="sphere" size="{_g(R)}" contype="0" conaffinity="0"/>
    </body>
{nl.join(bodies)}
  </worldbody>
  <actuator>
{nl.join(motors)}
  </actuator>
  <contact>
{nl.join(pairs)}
  </contact>
</mujoco>
"""
