"""The grasp a chain hand starts in, in MuJoCo: its joints, and torques that hold the ball in it.

* :func:`start_joints` — each finger's joints with its tip centre at
  O + (R + r) n̂ for its configured start normal n (``[hand] start_normals``),
  by Newton's method on MuJoCo's own Jacobian from starts spread over the
  soft limits; of the solutions found, the branch the daemon picks (its
  ``ChainHand::joints`` without a reference): the contact on the tip's
  contactable hemisphere, and of those the most margin inside the soft
  limits. The daemon then finds the measured joints on the branch it would
  command.
* :func:`holding_forces` — forces at the three contacts that hold the
  object's weight with no net torque about its centre and stay well inside
  the friction cones: the least-norm forces that balance the weight plus a
  squeeze along each line between two contacts (such a pair of forces is
  internal: no net force or torque), the squeezes (one per pair, on a
  grid) that keep every force within half its friction cone with the
  least largest force.
* :func:`holding_torques` — the joint torques J_pᵀ f + g(q) of those forces
  (J_p the contact point's Jacobian): what the plant commands until the
  daemon commands it.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

import numpy as np

from .trifinger_hand import F64, TriFingerHand

#: Starts per joint for the inverse kinematics (spread over the soft limits).
STARTS_PER_JOINT = 3
#: Newton iterations per start, and the tip error that counts as reached [m].
NEWTON_ITERATIONS = 30
REACHED = 1e-12
#: A contact is on the tip's hemisphere (pole: −z of the tip frame) within this angle [rad].
TIP_PATCH = math.radians(90.0)


def _unit(v: Sequence[float] | F64) -> F64:
    a = np.asarray(v, dtype=np.float64)
    return a / np.linalg.norm(a)


def contact_targets(hand: TriFingerHand, normals: Sequence[Sequence[float]]) -> list[F64]:
    """Each finger's tip-centre target O + (R + r) n̂ [m, hand frame]."""
    spec = hand.hand
    centre = np.asarray(spec.object_centre)
    return [centre + (spec.object_radius + f.tip_radius) * _unit(n) for f, n in zip(spec.fingers, normals, strict=True)]


def _solve(hand: TriFingerHand, k: int, target: F64, q: F64, seed: F64) -> F64 | None:
    """Newton from ``seed`` for finger ``k`` (the other fingers at ``q``); None if it does not converge."""
    idx = slice(3 * k, 3 * k + 3)
    x = q.copy()
    x[idx] = seed
    for _ in range(NEWTON_ITERATIONS):
        hand.reset(x)
        err = target - hand.tip_position(k)
        if float(np.linalg.norm(err)) < REACHED:
            return np.asarray(x[idx])
        j = hand.point_jacobian(k, hand.tip_position(k))
        try:
            x[idx] += np.linalg.solve(j, err)
        except np.linalg.LinAlgError:
            return None
    return None


def _patch_angle(hand: TriFingerHand, k: int, q: F64, normal: F64) -> float:
    """The angle of the contact on finger ``k``'s tip from its pole (−z of the tip frame) at joints ``q``."""
    hand.reset(q)
    rot = np.asarray(hand.data.xmat[hand.tip_bodies[k]]).reshape(3, 3)
    local = rot.T @ (-normal)
    return math.acos(max(-1.0, min(1.0, -float(local[2]))))


def start_joints(hand: TriFingerHand, normals: Sequence[Sequence[float]]) -> F64:
    """Every finger's joints for the start grasp (module docs); ValueError if a finger cannot reach it."""
    targets = contact_targets(hand, normals)
    lower, upper = hand.lower, hand.upper
    q = np.zeros(hand.n)
    for k, target in enumerate(targets):
        idx = slice(3 * k, 3 * k + 3)
        lo, hi = lower[idx], upper[idx]
        grid = [np.linspace(a, b, STARTS_PER_JOINT + 2)[1:-1] for a, b in zip(lo, hi)]
        best: tuple[float, F64] | None = None
        for seed in itertools.product(*grid):
            sol = _solve(hand, k, target, q, np.array(seed))
            if sol is None or np.any(sol < lo) or np.any(sol > hi):
                continue
            trial = q.copy()
            trial[idx] = sol
            if _patch_angle(hand, k, trial, _unit(normals[k])) > TIP_PATCH:
                continue
            margin = float(np.min(np.minimum(sol - lo, hi - sol)))
            if best is None or margin > best[0] + 1e-9:
                best = (margin, sol)
        if best is None:
            raise ValueError(f"finger {k}: no joints inside the soft limits put its tip on start normal {normals[k]}")
        q[idx] = best[1]
    hand.reset(q)
    return q


def holding_forces(points: Sequence[F64], weight: F64, mu: float, cone_share: float = 0.5) -> list[F64]:
    """Forces at three ``points`` (contacts relative to the object's centre) that hold ``weight``
    (the gravity force on the object) with no torque, each within ``cone_share`` of its friction
    cone where a squeeze can make it so (else the least share found), with the least largest force."""
    p = [np.asarray(x, dtype=np.float64) for x in points]
    a = np.zeros((6, 3 * len(p)))
    for k, pk in enumerate(p):
        a[0:3, 3 * k : 3 * k + 3] = np.eye(3)
        a[3:6, 3 * k : 3 * k + 3] = np.array([[0.0, -pk[2], pk[1]], [pk[2], 0.0, -pk[0]], [-pk[1], pk[0], 0.0]])
    b = np.concatenate([-np.asarray(weight, dtype=np.float64), np.zeros(3)])
    base = np.linalg.lstsq(a, b, rcond=None)[0].reshape(len(p), 3)
    pairs = list(itertools.combinations(range(len(p)), 2))
    # A squeeze s along the line between contacts i and j pushes i towards j and j towards i.
    lines = [_unit(p[j] - p[i]) for i, j in pairs]
    inward = np.array([-_unit(pk) for pk in p])
    top = 20.0 * (float(np.linalg.norm(weight)) or 1.0)
    grid = np.linspace(0.0, top, 41)
    s = np.array(list(itertools.product(grid, repeat=len(pairs))))  # candidates × pairs
    f = np.repeat(base[None, :, :], len(s), axis=0)
    for c, ((i, j), e) in enumerate(zip(pairs, lines)):
        f[:, i, :] += s[:, c, None] * e
        f[:, j, :] -= s[:, c, None] * e
    fn = np.einsum("ckx,kx->ck", f, inward)
    ft = np.linalg.norm(f - fn[:, :, None] * inward[None, :, :], axis=2)
    use = np.where(fn > 0.0, ft / (mu * np.maximum(fn, 1e-300)), np.inf).max(axis=1)
    largest = np.linalg.norm(f, axis=2).max(axis=1)
    ok = use <= cone_share
    best = int(np.argmin(np.where(ok, largest, np.inf))) if ok.any() else int(np.argmin(use))
    return [np.asarray(x) for x in f[best]]


def holding_torques(hand: TriFingerHand, q: F64, cone_share: float = 0.5) -> F64:
    """The joint torques that hold the ball at joints ``q`` (module docs), links' weight included."""
    hand.reset(q)
    spec = hand.hand
    centre = hand.object_position()
    tips = [hand.tip_position(k) for k in range(len(spec.fingers))]
    normals = [(t - centre) / np.linalg.norm(t - centre) for t in tips]
    points = [spec.object_radius * n for n in normals]
    weight = spec.object_mass * np.asarray(spec.gravity)
    forces = holding_forces(points, weight, spec.mu, cone_share)
    tau = hand.gravity_torque()
    for k, (t, n, f) in enumerate(zip(tips, normals, forces)):
        r = spec.fingers[k].tip_radius
        tau[3 * k : 3 * k + 3] += hand.point_jacobian(k, t - r * n).T @ f
    return tau
