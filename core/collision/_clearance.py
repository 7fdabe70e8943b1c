"""The certification walk's compiled kernels (numba): clearances, and states a clearance proves free.

Split from _kernels.py, whose placement and table kernels they use; cached on disk the same way.
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from ._kernels import _inside, apart, forward, gap, place, place_owner, set_mimics, tabled_clearance, unpack
from ._verdicts import CLEAR

# numba caches a kernel by this file's bytes alone; the line below changes them with the sources its
# kernels compile in (tests/foundation/test_kernel_inputs.py says what it must read).
# Compiled in (sha256): collision/_kernels.py 15ceb5d60f65, collision/_verdicts.py 5c11907276b0

__all__ = ["certify", "clearance"]


@numba.njit(cache=True)
def distance(kind: int, centre: Any, rot: Any, size: Any, p: Any) -> float:
    """Return the distance [m] from point `p` to an obstacle (box, sphere, cylinder; 0 inside it)."""
    radius = size[0] if kind == 1 else 0.0  # gap of a sphere obstacle: from its centre, less its radius
    return max(np.sqrt(gap(kind, centre, rot, size, p, 0.0) + radius * radius) - radius, 0.0)


@numba.njit(cache=True, inline="always")
def clearance(q: Any, model: Any, cap: float, scratch: Any) -> tuple[int, float]:
    """Return the spheres' verdict on configuration `q` (tables aside) and, if CLEAR, its clearance [m], at most `cap`.

    The clearance is the least distance from a checked sphere to an obstacle or to a sphere of
    an owner it is checked against: while no robot point moves (along its path) farther than
    that, no point of the geometry the spheres enclose reaches an obstacle or another owner's
    geometry. Two owners' distance changes by at most the motion of one relative to the other,
    which only the joints on the tree path between them cause, each once, so the sum that bounds
    a point's motion (core/collision/_certify.py) bounds it too. Not CLEAR: as `judge` says,
    COLLIDES if an inner ball proves it, else MAYBE.
    """
    rot, pos, world, iworld, owc, local, placed = scratch
    _, joints, spheres, owners, _, pairs, obstacles, check, _ = model
    centres, radii, sjoint, start = spheres
    ojoint, ocentre, oradius = owners
    okind, opos, orot, osize, _, oball = obstacles
    forward(q, joints, rot, pos, local)
    place(ocentre, ojoint, rot, pos, owc)
    placed[:] = False
    best = cap
    # Squared tests first (gap > 0: farther than the radius given): most balls are farther than `best`
    # from everything, and an owner's bounding ball is no nearer than its spheres.
    for o in range(len(oradius)):
        for b in range(len(okind)):
            if not check[o, b] or apart(owc[o], opos[b], oradius[o] + best + oball[b]) \
                    or gap(okind[b], opos[b], orot[b], osize[b], owc[o], oradius[o] + best) > 0.0:
                continue
            place_owner(o, start, sjoint, centres, rot, pos, world, placed)
            for s in range(start[o], start[o + 1]):
                if gap(okind[b], opos[b], orot[b], osize[b], world[s], radii[s] + best) > 0.0:
                    continue
                if gap(okind[b], opos[b], orot[b], osize[b], world[s], radii[s]) <= 0.0:  # as `judge` tests it
                    return _inside(model, rot, pos, iworld, owc), 0.0
                best = min(best, distance(okind[b], opos[b], orot[b], osize[b], world[s]) - radii[s])
    for i in range(len(pairs)):
        a, b = pairs[i, 0], pairs[i, 1]
        if apart(owc[a], owc[b], oradius[a] + oradius[b] + best):
            continue
        place_owner(a, start, sjoint, centres, rot, pos, world, placed)
        place_owner(b, start, sjoint, centres, rot, pos, world, placed)
        for t in range(start[b], start[b + 1]):
            if apart(world[t], owc[a], radii[t] + oradius[a] + best):
                continue
            for s in range(start[a], start[a + 1]):
                if apart(world[s], world[t], radii[s] + radii[t] + best):
                    continue
                if not apart(world[s], world[t], radii[s] + radii[t]):
                    return _inside(model, rot, pos, iworld, owc), 0.0
                dx, dy, dz = world[s, 0] - world[t, 0], world[s, 1] - world[t, 1], world[s, 2] - world[t, 2]
                best = min(best, np.sqrt(dx * dx + dy * dy + dz * dz) - radii[s] - radii[t])
    return CLEAR, best


@numba.njit(cache=True)
def certify(values: Any, travel: Any, cap: float, floor: float, floats: Any, ints: Any, head: Any, qs: Any, out: Any,
            radius: Any) -> int:
    """Write per state of a motion (rows of `values`) verdict, configuration and radius; return how many spheres judged.

    `travel[k]` bounds how far any robot point moves from the first state to state k (non-decreasing,
    core/collision/_certify.py). A state CLEAR with clearance c proves every later state whose travel
    is less than c beyond its own free under the spheres: those are not judged, only looked up in the
    distance tables (which need no kinematics), and read CLEAR if the tables say apart.
    `radius[k]` of a CLEAR state bounds from below every checked pair's distance there, so no
    robot point moving less than it (either way along the motion) reaches anything; 0 for the
    rest. Clearances are sought up to `cap`, and past the motion's end only up to `floor`.
    """
    base, group, continuous, model = unpack(floats, ints, head)
    tables, joints, spheres, owners, inner = model[0], model[1], model[2], model[3], model[4]
    nj = len(joints[0])
    scratch = (np.empty((nj, 3, 3)), np.empty((nj, 3)), np.empty((len(spheres[1]), 3)),
               np.empty((len(inner[1]), 3)), np.empty((len(owners[2]), 3)), np.empty((3, 3)),
               np.empty(len(owners[2]), dtype=np.bool_))
    covered, judged = -1.0, 0  # states with travel below `covered` are free under the spheres
    for k in range(len(values)):
        # Written out as in _kernels.judge: a helper per state costs more than the work (its docstring).
        q = qs[k]
        q[:] = base
        for i in range(len(group)):
            if continuous[i]:
                q[group[i]] = np.cos(values[k, i])
                q[group[i] + 1] = np.sin(values[k, i])
            else:
                q[group[i]] = values[k, i]
        set_mimics(q, values[k], model[8])
        out[k], tabled = tabled_clearance(q, tables)
        radius[k] = 0.0
        if out[k] != CLEAR:
            continue
        if travel[k] < covered:
            radius[k] = min(covered - travel[k], tabled)
            continue
        out[k], c = clearance(q, model, min(cap, max(travel[-1] - travel[k], floor)), scratch)
        judged += 1
        if out[k] == CLEAR:
            covered = travel[k] + c
            radius[k] = min(c, tabled)
    return judged
