"""The parts of the daemon's configuration file (``gaitd.toml``) a plant needs.

Why read the daemon's own file: a plant must simulate the hand the daemon
controls — same radii, friction, finger azimuths, load, period and IPC
namespace. Reading the one file both use removes a class of mismatches.
Defaults are those of ``deploy/gaitd.toml`` (the daemon validates the file;
this reader only takes what it needs and ignores the other keys). A chain
hand's plant also reads ``[hand]``: the description it simulates and the
grasp it starts in.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

from . import ipc
from .ipc import IpcSettings


@dataclass(frozen=True)
class Model:
    """``[model]``: the sphere, the fingertips, friction and the finger bases."""

    object_radius: float = 0.5
    fingertip_radius: float = 0.1
    friction_angle_deg: float = 20.0
    torsion_ratio: float = 0.1
    finger_azimuth_deg: tuple[float, float, float] = (0.0, 120.0, 240.0)
    contact_tolerance: float = 1e-4

    @property
    def mu(self) -> float:
        """Friction coefficient μ = tan θ."""
        return math.tan(math.radians(self.friction_angle_deg))

    @property
    def torsion(self) -> float:
        """Soft-finger torsion coefficient μ_t = ratio · r · μ [m] (spin torque ≤ μ_t · f_n)."""
        return self.torsion_ratio * self.fingertip_radius * self.mu


@dataclass(frozen=True)
class Load:
    """``[load]``: the object's weight and the grip bounds."""

    object_mass: float = 0.1
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    min_grip: float = 1.0
    max_grip: float = 20.0


@dataclass(frozen=True)
class PlantSection:
    """``[plant]``: which plant and its timing; unknown to older daemons."""

    kind: str = "embedded"
    timing: str = "realtime"
    lockstep_timeout_ms: float = 1000.0


@dataclass(frozen=True)
class HandSection:
    """``[hand]`` of a chain hand (``kind = "chains"``): its description and the grasp it starts in.

    ``description`` is the hand section's path, resolved against the configuration file's folder
    as the daemon resolves it; ``start_normals`` are the start contacts' outward normals on the
    object (not necessarily unit), one per finger; ``joint_kp`` and ``joint_kd`` the gains the
    daemon commands (its defaults: TriFingerPro's 9 and 0.01).
    """

    kind: str
    description: Path
    start_normals: tuple[tuple[float, float, float], ...]
    joint_kp: tuple[float, float, float] = (9.0, 9.0, 9.0)
    joint_kd: tuple[float, float, float] = (0.01, 0.01, 0.01)


@dataclass(frozen=True)
class DaemonConfig:
    """What a plant reads from the daemon's configuration."""

    model: Model = field(default_factory=Model)
    load: Load = field(default_factory=Load)
    tick_hz: float = 1000.0
    plant: PlantSection = field(default_factory=PlantSection)
    ipc: Mapping[str, Any] = field(default_factory=dict)
    path: str | None = None
    hand: HandSection | None = None

    @property
    def chains(self) -> bool:
        """The hand is a hand of finger chains (``[hand] kind = "chains"``)."""
        return self.hand is not None and self.hand.kind == "chains"

    @property
    def period(self) -> float:
        """Control period [s]."""
        return 1.0 / self.tick_hz

    @property
    def period_ns(self) -> int:
        """Control period [ns], rounded as the daemon rounds it (half away from zero)."""
        return math.floor(1e9 / self.tick_hz + 0.5)

    def ipc_settings(self) -> IpcSettings:
        """The daemon's IPC namespace, resolved as the daemon resolves it."""
        return ipc.resolve_section(self.ipc)


_Section = TypeVar("_Section", Model, Load, PlantSection)


def _take(section: Mapping[str, Any], cls: type[_Section], name: str) -> _Section:
    kwargs = {}
    for f in dataclasses.fields(cls):
        if f.name in section:
            v = section[f.name]
            if isinstance(v, list):
                v = tuple(float(x) for x in v)
            kwargs[f.name] = v
    try:
        return cls(**kwargs)
    except TypeError as e:  # pragma: no cover - dataclass signature errors
        raise ValueError(f"[{name}]: {e}") from e


def _vec3(v: Any, what: str) -> tuple[float, float, float]:
    if not isinstance(v, list) or len(v) != 3:
        raise ValueError(f"{what}: three numbers")
    return (float(v[0]), float(v[1]), float(v[2]))


def _hand(section: Mapping[str, Any], path: str | None) -> HandSection | None:
    """``[hand]``; None unless it describes a chain hand."""
    kind = str(section.get("kind", "fingertips"))
    if kind != "chains":
        return None
    if "description" not in section:
        raise ValueError('[hand] kind = "chains" needs description')
    base = Path(path).parent if path is not None else Path(".")
    normals = section.get("start_normals", [])
    if not isinstance(normals, list) or len(normals) != 3:
        raise ValueError("[hand] start_normals: one contact normal per finger, three")
    default = HandSection(kind, Path(), ())
    return HandSection(
        kind,
        base / str(section["description"]),
        tuple(_vec3(n, "[hand] start_normals") for n in normals),
        _vec3(section["joint_kp"], "[hand] joint_kp") if "joint_kp" in section else default.joint_kp,
        _vec3(section["joint_kd"], "[hand] joint_kd") if "joint_kd" in section else default.joint_kd,
    )


def parse(doc: Mapping[str, Any], path: str | None = None) -> DaemonConfig:
    """A :class:`DaemonConfig` from a parsed TOML document."""
    model = _take(doc.get("model", {}), Model, "model")
    if len(model.finger_azimuth_deg) != 3:
        raise ValueError("[model] finger_azimuth_deg needs three angles")
    load = _take(doc.get("load", {}), Load, "load")
    if len(load.gravity) != 3:
        raise ValueError("[load] gravity needs three components")
    tick_hz = float(doc.get("control", {}).get("tick_hz", 1000.0))
    if not (100.0 <= tick_hz <= 10000.0):
        raise ValueError(f"[control] tick_hz = {tick_hz}: must be in 100–10000 Hz")
    plant = _take(doc.get("plant", {}), PlantSection, "plant")
    hand = _hand(doc.get("hand", {}), path)
    return DaemonConfig(model, load, tick_hz, plant, dict(doc.get("ipc", {})), path, hand)


def load(path: str | Path | None) -> DaemonConfig:
    """Reads ``path`` (None: every default)."""
    if path is None:
        return DaemonConfig()
    with open(path, "rb") as fh:
        return parse(tomllib.load(fh), str(path))
