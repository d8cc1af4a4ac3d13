"""The package's modules import with only the core dependency (iceoryx2): numpy and MuJoCo are the
``mujoco`` extra's, eclipse-zenoh the ``remote`` extra's, imported only where they are used."""

from __future__ import annotations

import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1]
PYPROJECT = PACKAGE / "pyproject.toml"
#: Every module of the package that must work without the extras.
CORE = [
    "gaitd",
    "gaitd.schema",
    "gaitd.ipc",
    "gaitd.client",
    "gaitd.remote",
    "gaitd.plant",
    "gaitd.setpoint",
    "gaitd.config",
    "gaitd.hand",
    "gaitd.quat",
    "gaitd.trace",
    "gaitd.plants",
    "gaitd.plants.mujoco_scene",
    "gaitd.plants.trifinger_scene",
]
EXTRAS = ["numpy", "mujoco", "zenoh"]


def import_without_extras(modules: list[str]) -> subprocess.CompletedProcess[str]:
    """Imports ``modules`` in a fresh interpreter in which importing an extra raises ImportError."""
    code = (
        "import sys\n"
        f"for name in {EXTRAS!r}:\n"
        "    sys.modules[name] = None  # import raises ImportError\n"
        f"for m in {modules!r}:\n"
        "    __import__(m)\n"
    )
    # This checkout's package first, whichever one the interpreter has installed.
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(PACKAGE), os.environ.get("PYTHONPATH", "")])}
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False, env=env)


def test_the_core_imports_without_the_extras() -> None:
    r = import_without_extras(CORE)
    assert r.returncode == 0, r.stderr


@pytest.mark.parametrize("module", ["gaitd.plants.mujoco_plant", "gaitd.plants.mujoco", "gaitd.plants.trifinger_hand"])
def test_the_mujoco_hand_needs_its_extra(module: str) -> None:
    """The check above can fail: the MuJoCo hand does import an extra."""
    r = import_without_extras([module])
    assert r.returncode != 0
    assert "ImportError" in r.stderr or "ModuleNotFoundError" in r.stderr


def test_the_core_dependencies_are_only_iceoryx2() -> None:
    project = tomllib.loads(PYPROJECT.read_text(encoding="utf-8"))["project"]
    assert [d.split("==")[0] for d in project["dependencies"]] == ["iceoryx2"]
    extras = project["optional-dependencies"]
    assert {d.split("==")[0] for d in extras["mujoco"]} == {"mujoco", "numpy"}
    assert {d.split("==")[0] for d in extras["remote"]} == {"eclipse-zenoh"}
    for deps in [project["dependencies"], *extras.values()]:
        assert all("==" in d for d in deps), f"every dependency is pinned exactly: {deps}"
