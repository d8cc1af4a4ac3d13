"""Unit quaternions [w, x, y, z] (Hamilton, world-from-body) on plain floats.

Why plain floats and not numpy: a plant handles a handful of quaternions per
control period, where numpy's per-call overhead dominates; these helpers
are a few hundred nanoseconds each and need no dependency.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

Quat = tuple[float, float, float, float]
Vec = tuple[float, float, float]

IDENTITY: Quat = (1.0, 0.0, 0.0, 0.0)


def mul(a: Sequence[float], b: Sequence[float]) -> Quat:
    """Hamilton product a ⊗ b."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def conj(q: Sequence[float]) -> Quat:
    """Conjugate (the inverse of a unit quaternion)."""
    return (q[0], -q[1], -q[2], -q[3])


def norm(q: Sequence[float]) -> float:
    """Euclidean norm."""
    return math.sqrt(sum(c * c for c in q))


def normalize(q: Sequence[float]) -> Quat:
    """q / |q|."""
    n = norm(q)
    return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)


def rotate(q: Sequence[float], v: Sequence[float]) -> Vec:
    """q v q* for a unit quaternion q."""
    w, x, y, z = q
    vx, vy, vz = v
    # t = 2 (q_vec × v); v' = v + w t + q_vec × t
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return (
        vx + w * tx + (y * tz - z * ty),
        vy + w * ty + (z * tx - x * tz),
        vz + w * tz + (x * ty - y * tx),
    )


def from_rotvec(r: Sequence[float]) -> Quat:
    """exp: rotation vector (axis · angle) to quaternion."""
    a = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    if a < 1e-12:
        return normalize((1.0, 0.5 * r[0], 0.5 * r[1], 0.5 * r[2]))
    s = math.sin(0.5 * a) / a
    return (math.cos(0.5 * a), r[0] * s, r[1] * s, r[2] * s)


def to_rotvec(q: Sequence[float]) -> Vec:
    """log: quaternion to rotation vector, the shorter way round (angle ≤ π)."""
    w, x, y, z = q
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    s = math.sqrt(x * x + y * y + z * z)
    if s < 1e-12:
        return (2.0 * x, 2.0 * y, 2.0 * z)
    k = 2.0 * math.atan2(s, w) / s
    return (x * k, y * k, z * k)


def from_axis_angle(axis: Sequence[float], angle: float) -> Quat:
    """Rotation by ``angle`` [rad] about ``axis`` (any non-zero length)."""
    n = math.sqrt(sum(c * c for c in axis))
    return from_rotvec(tuple(c / n * angle for c in axis))


def angle_between(a: Sequence[float], b: Sequence[float]) -> float:
    """Rotation angle [rad] from a to b, in [0, π] (sign of either ignored)."""
    d = abs(sum(x * y for x, y in zip(a, b))) / (norm(a) * norm(b))
    return 2.0 * math.acos(min(1.0, d))


def slerp(a: Sequence[float], b: Sequence[float], s: float) -> Quat:
    """Spherical interpolation, the shorter way, s in [0, 1]."""
    if sum(x * y for x, y in zip(a, b)) < 0.0:
        b = tuple(-c for c in b)
    r = to_rotvec(mul(b, conj(a)))
    return normalize(mul(from_rotvec(tuple(c * s for c in r)), a))


def arc(a: Sequence[float], b: Sequence[float]) -> Quat:
    """The shortest rotation taking unit vector a onto unit vector b."""
    w = 1.0 + a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    if w < 1e-9:  # antiparallel: a half turn about any axis ⟂ a
        axis = (0.0, -a[2], a[1]) if abs(a[0]) < 0.9 else (-a[1], a[0], 0.0)
        return from_axis_angle(axis, math.pi)
    v = (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
    return normalize((w, v[0], v[1], v[2]))


def from_matrix_columns(x: Sequence[float], y: Sequence[float], z: Sequence[float]) -> Quat:
    """The rotation whose matrix has columns x, y, z (a right-handed orthonormal frame)."""
    m00, m10, m20 = x
    m01, m11, m21 = y
    m02, m12, m22 = z
    t = m00 + m11 + m22
    if t > 0.0:
        s = 2.0 * math.sqrt(t + 1.0)
        q = (0.25 * s, (m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s)
    elif m00 > m11 and m00 > m22:
        s = 2.0 * math.sqrt(1.0 + m00 - m11 - m22)
        q = ((m21 - m12) / s, 0.25 * s, (m01 + m10) / s, (m02 + m20) / s)
    elif m11 > m22:
        s = 2.0 * math.sqrt(1.0 + m11 - m00 - m22)
        q = ((m02 - m20) / s, (m01 + m10) / s, 0.25 * s, (m12 + m21) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + m22 - m00 - m11)
        q = ((m10 - m01) / s, (m02 + m20) / s, (m12 + m21) / s, 0.25 * s)
    return normalize(q)
