"""What a plant reads from ``gaitd.toml`` (``gaitd.config``) and where the daemon's IPC resources
are (``gaitd.ipc``), resolved as the daemon resolves them."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import pytest

from gaitd import config, ipc

DEPLOY = Path(__file__).resolve().parents[3] / "deploy" / "gaitd.toml"


def test_no_file_is_every_default() -> None:
    c = config.load(None)
    assert c == config.DaemonConfig()
    assert c.tick_hz == 1000.0 and c.period == 0.001 and c.period_ns == 1_000_000
    assert c.model.mu == pytest.approx(math.tan(math.radians(20.0)))
    assert c.model.torsion == pytest.approx(0.1 * 0.1 * math.tan(math.radians(20.0)))


def test_the_defaults_are_the_example_files() -> None:
    """``deploy/gaitd.toml`` shows the daemon's defaults: a plant reading no file assumes the same hand."""
    c = config.load(DEPLOY)
    d = config.DaemonConfig()
    assert c.model == d.model
    assert c.load == d.load
    assert c.tick_hz == d.tick_hz
    assert c.plant == d.plant
    assert c.path == str(DEPLOY)


def test_values_are_read_and_other_keys_ignored(tmp_path: Path) -> None:
    p = tmp_path / "gaitd.toml"
    p.write_text(
        """
[model]
object_radius = 0.04
finger_azimuth_deg = [0, 90, 180]
roll_limit_deg = 45.0

[load]
gravity = [0.0, 0.0, 0]
max_grip = 8.0

[control]
tick_hz = 1500

[plant]
kind = "shm"
timing = "lockstep"

[ipc]
service_prefix = "lab/hand-2"
root_path = ""
""",
        encoding="utf-8",
    )
    c = config.load(p)
    assert c.model.object_radius == 0.04
    assert c.model.fingertip_radius == 0.1
    assert c.model.finger_azimuth_deg == (0.0, 90.0, 180.0)
    assert all(isinstance(a, float) for a in c.model.finger_azimuth_deg)
    assert c.load.gravity == (0.0, 0.0, 0.0) and c.load.max_grip == 8.0
    assert c.plant == config.PlantSection(kind="shm", timing="lockstep")
    # 1e9 / 1500 = 666666.67: rounded half away from zero, as the daemon does.
    assert c.period_ns == 666_667
    s = c.ipc_settings()
    assert s.service_prefix == "lab/hand-2"


@pytest.mark.parametrize(
    ("doc", "why"),
    [
        ("[model]\nfinger_azimuth_deg = [0.0, 120.0]\n", "three angles"),
        ("[load]\ngravity = [0.0, -9.81]\n", "three components"),
        ("[control]\ntick_hz = 50.0\n", "100–10000 Hz"),
        ("[control]\ntick_hz = 20000.0\n", "100–10000 Hz"),
    ],
)
def test_refused(doc: str, why: str) -> None:
    with pytest.raises(ValueError, match=why):
        config.parse(tomllib.loads(doc))


def test_period_rounding_half_away_from_zero() -> None:
    assert config.DaemonConfig(tick_hz=3000.0).period_ns == 333_333
    assert config.DaemonConfig(tick_hz=2000.0).period_ns == 500_000
    assert config.DaemonConfig(tick_hz=1500.0).period_ns == 666_667


# --------------------------------------------------------------------------- ipc


def test_explicit_beats_environment_beats_default() -> None:
    env = {ipc.ENV_PREFIX: "from-env", ipc.ENV_ROOT_PATH: "/env/root", ipc.ENV_FILE_PREFIX: "env_"}
    s = ipc.resolve("explicit", "/explicit/root/", "explicit_", env=env)
    assert s == ipc.IpcSettings("explicit", "/explicit/root/", "explicit_", None)
    s = ipc.resolve(env=env)
    assert s == ipc.IpcSettings("from-env", "/env/root/", "env_", None)  # a root path ends with '/'
    s = ipc.resolve(root_path="/r", env={})
    assert (s.service_prefix, s.file_prefix) == ("gaitd", ipc.DEFAULT_FILE_PREFIX)


def test_empty_strings_count_as_unset() -> None:
    env = {ipc.ENV_PREFIX: "", ipc.ENV_ROOT_PATH: "", ipc.ENV_FILE_PREFIX: ""}
    s = ipc.resolve("", "/r", "", env=env)
    assert (s.service_prefix, s.root_path, s.file_prefix) == ("gaitd", "/r/", "gaitd_")
    s = ipc.resolve_section({"service_prefix": "", "root_path": "/x", "file_prefix": ""}, env={})
    assert (s.service_prefix, s.root_path, s.file_prefix) == ("gaitd", "/x/", "gaitd_")


def test_default_root_path() -> None:
    assert ipc.default_root_path(0, run_dir_exists=False) == ipc.SERVICE_ROOT_PATH
    assert ipc.default_root_path(1000, run_dir_exists=True) == ipc.SERVICE_ROOT_PATH
    assert ipc.default_root_path(1000, run_dir_exists=False) == "/tmp/gaitd-1000/iceoryx2/"


@pytest.mark.parametrize(
    ("prefix", "root", "file_prefix", "why"),
    [
        ("bad prefix", "/r", "p_", "service prefix"),
        ("x" * 201, "/r", "p_", "service prefix"),
        ("ok", "relative/root", "p_", "absolute path"),
        ("ok", "/r", "a/b", "plain file name"),
    ],
)
def test_refused_settings(prefix: str, root: str, file_prefix: str, why: str) -> None:
    with pytest.raises(ipc.IpcError, match=why):
        ipc.resolve(prefix, root, file_prefix, env={})


def test_a_chain_hand_is_read_with_its_description_beside_the_file(tmp_path: Path) -> None:
    shipped = DEPLOY.parent / "hands" / "trifingerpro" / "gaitd.toml"
    c = config.load(shipped)
    assert c.chains and c.hand is not None
    assert c.hand.description == shipped.parent / "hand.toml" and c.hand.description.is_file()
    assert c.hand.start_normals == ((-0.07, 0.07, 1.0), (0.55, -0.57, -0.61), (-0.64, 0.66, 0.40))
    assert (c.hand.joint_kp, c.hand.joint_kd) == ((9.0,) * 3, (0.01,) * 3)
    p = tmp_path / "gaitd.toml"
    p.write_text(
        '[hand]\nkind = "chains"\ndescription = "sub/hand.toml"\nstart_normals = [[0, 0, 1], [1, 0, 0], [0, 1, 0]]\n'
        "joint_kp = [2, 3, 4]\n"
    )
    c = config.load(p)
    assert c.hand is not None and c.hand.description == tmp_path / "sub" / "hand.toml"
    assert c.hand.joint_kp == (2.0, 3.0, 4.0) and c.hand.joint_kd == (0.01,) * 3
    assert not config.load(DEPLOY).chains and config.load(DEPLOY).hand is None
    p.write_text('[hand]\nkind = "chains"\ndescription = "hand.toml"\nstart_normals = [[0, 0, 1]]\n')
    with pytest.raises(ValueError, match="start_normals"):
        config.load(p)
