"""Quaternion helpers (``gaitd.quat``): products, rotations, exp/log, interpolation, frames."""

from __future__ import annotations

import math
from collections.abc import Sequence

import pytest

from gaitd import quat

TOL = 1e-12


def close(a: Sequence[float], b: Sequence[float], tol: float = TOL) -> bool:
    return len(a) == len(b) and all(abs(x - y) <= tol for x, y in zip(a, b, strict=True))


def same_rotation(a: Sequence[float], b: Sequence[float], tol: float = 1e-9) -> bool:
    """q and −q are one rotation."""
    return close(a, b, tol) or close(a, [-c for c in b], tol)


QUARTER_Z = (math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))  # +90° about z


def test_product_is_hamilton() -> None:
    i, j, k = (0.0, 1.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0), (0.0, 0.0, 0.0, 1.0)
    assert close(quat.mul(i, j), k)
    assert close(quat.mul(j, i), (0.0, 0.0, 0.0, -1.0))
    assert close(quat.mul(j, k), i)
    assert close(quat.mul(k, i), j)
    assert close(quat.mul(i, i), (-1.0, 0.0, 0.0, 0.0))
    assert close(quat.mul(quat.IDENTITY, QUARTER_Z), QUARTER_Z)


def test_rotate_turns_vectors_world_from_body() -> None:
    assert close(quat.rotate(QUARTER_Z, (1.0, 0.0, 0.0)), (0.0, 1.0, 0.0))
    assert close(quat.rotate(QUARTER_Z, (0.0, 1.0, 0.0)), (-1.0, 0.0, 0.0))
    assert close(quat.rotate(QUARTER_Z, (0.0, 0.0, 2.0)), (0.0, 0.0, 2.0))
    # The conjugate turns back; a product turns one rotation after the other.
    v = (0.3, -1.2, 0.7)
    assert close(quat.rotate(quat.conj(QUARTER_Z), quat.rotate(QUARTER_Z, v)), v)
    assert close(quat.rotate(quat.mul(QUARTER_Z, QUARTER_Z), (1.0, 0.0, 0.0)), (-1.0, 0.0, 0.0))


def test_normalize_and_norm() -> None:
    q = quat.normalize((2.0, 0.0, 0.0, 2.0))
    assert quat.norm(q) == pytest.approx(1.0, abs=TOL)
    assert close(q, (math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5)))


@pytest.mark.parametrize(
    "r",
    [(0.0, 0.0, math.pi / 2), (0.4, -0.2, 1.1), (1e-14, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 3.0, 0.0)],
)
def test_rotvec_round_trip(r: tuple[float, float, float]) -> None:
    q = quat.from_rotvec(r)
    assert quat.norm(q) == pytest.approx(1.0, abs=TOL)
    assert close(quat.to_rotvec(q), r, 1e-9)


def test_from_rotvec_is_the_axis_angle_rotation() -> None:
    assert same_rotation(quat.from_rotvec((0.0, 0.0, math.pi / 2)), QUARTER_Z)
    assert same_rotation(quat.from_axis_angle((0.0, 0.0, 5.0), math.pi / 2), QUARTER_Z)


def test_to_rotvec_takes_the_shorter_way() -> None:
    # −q is the same rotation: the log must not return the 2π − θ one.
    q = tuple(-c for c in QUARTER_Z)
    assert close(quat.to_rotvec(q), (0.0, 0.0, math.pi / 2), 1e-12)
    assert math.sqrt(sum(c * c for c in quat.to_rotvec(quat.from_rotvec((0.0, 0.0, 1.5 * math.pi))))) <= math.pi


def test_angle_between_ignores_sign_and_scale() -> None:
    assert quat.angle_between(quat.IDENTITY, QUARTER_Z) == pytest.approx(math.pi / 2, abs=1e-12)
    assert quat.angle_between(QUARTER_Z, [-c for c in QUARTER_Z]) == pytest.approx(0.0, abs=1e-6)
    assert quat.angle_between((2.0, 0.0, 0.0, 0.0), QUARTER_Z) == pytest.approx(math.pi / 2, abs=1e-12)


def test_slerp_ends_midpoint_and_shorter_way() -> None:
    assert same_rotation(quat.slerp(quat.IDENTITY, QUARTER_Z, 0.0), quat.IDENTITY)
    assert same_rotation(quat.slerp(quat.IDENTITY, QUARTER_Z, 1.0), QUARTER_Z)
    eighth = quat.from_axis_angle((0.0, 0.0, 1.0), math.pi / 4)
    assert same_rotation(quat.slerp(quat.IDENTITY, QUARTER_Z, 0.5), eighth)
    # The far representative of the target: still the 45° way, not the 135° one.
    far = tuple(-c for c in QUARTER_Z)
    assert same_rotation(quat.slerp(quat.IDENTITY, far, 0.5), eighth)


@pytest.mark.parametrize(
    ("a", "b"),
    [
        ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
        ((0.0, 0.0, 1.0), (0.6, 0.0, 0.8)),
        ((1.0, 0.0, 0.0), (1.0, 0.0, 0.0)),
        ((1.0, 0.0, 0.0), (-1.0, 0.0, 0.0)),  # antiparallel
        ((0.0, 1.0, 0.0), (0.0, -1.0, 0.0)),  # antiparallel, the other branch
    ],
)
def test_arc_takes_a_onto_b(a: tuple[float, float, float], b: tuple[float, float, float]) -> None:
    q = quat.arc(a, b)
    assert quat.norm(q) == pytest.approx(1.0, abs=TOL)
    assert close(quat.rotate(q, a), b, 1e-9)


def test_arc_is_the_shortest_rotation() -> None:
    a, b = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)
    assert quat.angle_between(quat.IDENTITY, quat.arc(a, b)) == pytest.approx(math.pi / 2, abs=1e-12)


@pytest.mark.parametrize(
    "q",
    [
        quat.IDENTITY,  # trace > 0
        (0.0, 1.0, 0.0, 0.0),  # half turn about x: m00 largest
        (0.0, 0.0, 1.0, 0.0),  # about y: m11 largest
        (0.0, 0.0, 0.0, 1.0),  # about z: m22 largest
        quat.normalize((0.1, 0.7, -0.5, 0.3)),
        quat.normalize((-0.2, 0.1, 0.9, -0.4)),
    ],
)
def test_from_matrix_columns_inverts_the_rotation_matrix(q: tuple[float, float, float, float]) -> None:
    x = quat.rotate(q, (1.0, 0.0, 0.0))
    y = quat.rotate(q, (0.0, 1.0, 0.0))
    z = quat.rotate(q, (0.0, 0.0, 1.0))
    assert same_rotation(quat.from_matrix_columns(x, y, z), q)
