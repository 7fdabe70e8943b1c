"""The sphere filter's compiled kernels (numba), at module level so numba caches them on disk.

Imported only by core/sphere_check.py when a filter is first built: importing numba and
loading these costs ~1 s, which commands that do not plan never pay. Arrays come in
tuples by what they describe (see SphereFilter for their contents).
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from moveplan.core.sphere_check import CLEAR, COLLIDES, MAYBE

__all__ = ["clear", "tabled"]


@numba.njit(cache=True)
def gap(kind: int, centre: Any, rot: Any, size: Any, p: Any, radius: float) -> float:
    """Return the distance from a ball to an obstacle (box, sphere, cylinder), <= 0 when they touch."""
    d0, d1, d2 = p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]
    x = rot[0, 0] * d0 + rot[1, 0] * d1 + rot[2, 0] * d2
    y = rot[0, 1] * d0 + rot[1, 1] * d1 + rot[2, 1] * d2
    z = rot[0, 2] * d0 + rot[1, 2] * d1 + rot[2, 2] * d2
    if kind == 0:
        ex = max(abs(x) - size[0], 0.0)
        ey = max(abs(y) - size[1], 0.0)
        ez = max(abs(z) - size[2], 0.0)
        return np.sqrt(ex * ex + ey * ey + ez * ez) - radius
    if kind == 1:
        return np.sqrt(x * x + y * y + z * z) - size[0] - radius
    er = max(np.sqrt(x * x + y * y) - size[0], 0.0)
    ez = max(abs(z) - size[1], 0.0)
    return np.sqrt(er * er + ez * ez) - radius

@numba.njit(cache=True)
def tabled(q: Any, tables: Any) -> int:
    """Return CLEAR if every tabulated pair is apart at `q`, COLLIDES if one surely touches, else MAYBE."""
    axes, start, step, count, offset, margin, distance = tables
    verdict = CLEAR
    for p in range(len(offset)):
        flat = 0
        for axis in range(2):
            if axes[p, axis] < 0:
                continue
            x = (q[axes[p, axis]] - start[p, axis]) / step[p, axis]
            if x < -0.5 or x >= count[p, axis] - 0.5:
                return MAYBE  # off the grid, where the margin does not hold
            flat = flat * count[p, axis] + int(x + 0.5)
        d = distance[offset[p] + flat]
        if d < -margin[p]:
            return COLLIDES
        if d <= margin[p]:
            verdict = MAYBE
    return verdict


@numba.njit(cache=True)
def forward(q: Any, joints: Any, rot: Any, pos: Any) -> None:
    """Write every joint's world rotation and position at configuration `q` into `rot`, `pos` (joint 0: world)."""
    parents, kinds, axes, iq, prot, ptrans = joints
    rot[0] = 0.0
    for r in range(3):
        rot[0, r, r] = 1.0
    pos[0] = 0.0
    local = np.empty((3, 3))
    for j in range(1, len(parents)):
        # local = placement rotation * joint motion
        kind = kinds[j]
        a = axes[j]
        if kind == 2:
            for r in range(3):
                for c in range(3):
                    local[r, c] = prot[j, r, c]
            shift = q[iq[j]]
            t0 = ptrans[j, 0] + (prot[j, 0, 0] * a[0] + prot[j, 0, 1] * a[1] + prot[j, 0, 2] * a[2]) * shift
            t1 = ptrans[j, 1] + (prot[j, 1, 0] * a[0] + prot[j, 1, 1] * a[1] + prot[j, 1, 2] * a[2]) * shift
            t2 = ptrans[j, 2] + (prot[j, 2, 0] * a[0] + prot[j, 2, 1] * a[1] + prot[j, 2, 2] * a[2]) * shift
        else:
            if kind == 3:
                cs, sn = q[iq[j]], q[iq[j] + 1]
            else:
                cs, sn = np.cos(q[iq[j]]), np.sin(q[iq[j]])
            # Rodrigues: R = c I + s [a]x + (1 - c) a a^T
            v = 1.0 - cs
            m00 = cs + a[0] * a[0] * v
            m01 = a[0] * a[1] * v - a[2] * sn
            m02 = a[0] * a[2] * v + a[1] * sn
            m10 = a[1] * a[0] * v + a[2] * sn
            m11 = cs + a[1] * a[1] * v
            m12 = a[1] * a[2] * v - a[0] * sn
            m20 = a[2] * a[0] * v - a[1] * sn
            m21 = a[2] * a[1] * v + a[0] * sn
            m22 = cs + a[2] * a[2] * v
            for r in range(3):
                p0, p1, p2 = prot[j, r, 0], prot[j, r, 1], prot[j, r, 2]
                local[r, 0] = p0 * m00 + p1 * m10 + p2 * m20
                local[r, 1] = p0 * m01 + p1 * m11 + p2 * m21
                local[r, 2] = p0 * m02 + p1 * m12 + p2 * m22
            t0, t1, t2 = ptrans[j, 0], ptrans[j, 1], ptrans[j, 2]
        p = parents[j]
        for r in range(3):
            for c in range(3):
                rot[j, r, c] = rot[p, r, 0] * local[0, c] + rot[p, r, 1] * local[1, c] + rot[p, r, 2] * local[2, c]
            pos[j, r] = pos[p, r] + rot[p, r, 0] * t0 + rot[p, r, 1] * t1 + rot[p, r, 2] * t2


@numba.njit(cache=True)
def place(centres: Any, joint: Any, rot: Any, pos: Any, world: Any) -> None:
    """Write the world position of each centre (in its joint's frame) into `world`."""
    for s in range(len(joint)):
        j = joint[s]
        for r in range(3):
            world[s, r] = pos[j, r] + rot[j, r, 0] * centres[s, 0] + rot[j, r, 1] * centres[s, 1] \
                + rot[j, r, 2] * centres[s, 2]


@numba.njit(cache=True)
def place_owner(o: int, start: Any, joint: Any, centres: Any, rot: Any, pos: Any, world: Any, placed: Any) -> None:
    """Write owner `o`'s sphere centres in the world frame into `world`, once per state (`placed`)."""
    if placed[o]:
        return
    placed[o] = True
    for s in range(start[o], start[o + 1]):
        j = joint[s]
        for r in range(3):
            world[s, r] = pos[j, r] + rot[j, r, 0] * centres[s, 0] + rot[j, r, 1] * centres[s, 1] \
                + rot[j, r, 2] * centres[s, 2]


@numba.njit(cache=True)
def balls_touch(world: Any, radii: Any, a: Any, b: Any, strict: bool) -> bool:
    """Return True if a ball in index range `a` touches (with `strict`: overlaps) one in range `b`."""
    for s in range(a[0], a[1]):
        for t in range(b[0], b[1]):
            dx, dy, dz = world[s, 0] - world[t, 0], world[s, 1] - world[t, 1], world[s, 2] - world[t, 2]
            reach = radii[s] + radii[t]
            d2 = dx * dx + dy * dy + dz * dz
            if d2 < reach * reach or (not strict and d2 == reach * reach):
                return True
    return False


@numba.njit(cache=True)
def clear(values: Any, base: Any, group: Any, continuous: Any, tables: Any, joints: Any, spheres: Any,
          owners: Any, inner: Any, pairs: Any, obstacles: Any, check: Any, qs: Any, out: Any, stop: bool) -> int:
    """Write per group state (rows of `values`) its configuration into `qs` and its verdict into `out`.

    CLEAR: no sphere touches an obstacle or another owner's sphere, and the tables say
    apart. COLLIDES: a tabulated pair, or a ball inside a hull, surely touches something
    (an obstacle it is checked against, or another owner's inner ball). Else MAYBE.
    Returns how many states were judged: all, or with `stop` up to the first COLLIDES.
    """
    for k in range(len(values)):
        qs[k] = base
        for i in range(len(group)):
            if continuous[i]:
                qs[k, group[i]] = np.cos(values[k, i])
                qs[k, group[i] + 1] = np.sin(values[k, i])
            else:
                qs[k, group[i]] = values[k, i]
    centres, radii, sjoint, start = spheres
    ojoint, ocentre, oradius = owners
    icentres, iradii, ijoint, istart = inner
    okind, opos, orot, osize, osolid = obstacles
    nj = len(joints[0])
    rot = np.empty((nj, 3, 3))
    pos = np.empty((nj, 3))
    world = np.empty((len(radii), 3))
    iworld = np.empty((len(iradii), 3))
    owc = np.empty((len(oradius), 3))
    near = np.empty(len(radii), dtype=np.int64)
    placed = np.empty(len(oradius), dtype=np.bool_)
    for k in range(len(qs)):
        q = qs[k]
        verdict = tabled(q, tables)
        if verdict != CLEAR:
            out[k] = verdict
            if stop and verdict == COLLIDES:
                return k + 1
            continue
        forward(q, joints, rot, pos)
        place(ocentre, ojoint, rot, pos, owc)
        # An owner's spheres are placed only when something comes within its bounding ball.
        placed[:] = False
        free = True
        for o in range(len(oradius)):
            if not free:
                break
            for b in range(len(okind)):
                if not check[o, b]:
                    continue
                if gap(okind[b], opos[b], orot[b], osize[b], owc[o], oradius[o]) > 0.0:
                    continue
                place_owner(o, start, sjoint, centres, rot, pos, world, placed)
                for s in range(start[o], start[o + 1]):
                    if gap(okind[b], opos[b], orot[b], osize[b], world[s], radii[s]) <= 0.0:
                        free = False
                        break
                if not free:
                    break
        for i in range(len(pairs)):
            if not free:
                break
            a, b = pairs[i, 0], pairs[i, 1]
            dx, dy, dz = owc[a, 0] - owc[b, 0], owc[a, 1] - owc[b, 1], owc[a, 2] - owc[b, 2]
            reach = oradius[a] + oradius[b]
            if dx * dx + dy * dy + dz * dz > reach * reach:
                continue
            place_owner(a, start, sjoint, centres, rot, pos, world, placed)
            place_owner(b, start, sjoint, centres, rot, pos, world, placed)
            # Only b's spheres that reach a's bounding ball can touch one of a's spheres.
            count = 0
            for t in range(start[b], start[b + 1]):
                dx, dy, dz = world[t, 0] - owc[a, 0], world[t, 1] - owc[a, 1], world[t, 2] - owc[a, 2]
                reach = radii[t] + oradius[a]
                if dx * dx + dy * dy + dz * dz <= reach * reach:
                    near[count] = t
                    count += 1
            for n in range(count):
                if balls_touch(world, radii, (start[a], start[a + 1]), (near[n], near[n] + 1), False):
                    free = False
                    break
        if free:
            out[k] = CLEAR
            continue
        out[k] = MAYBE
        # Most states the search cannot clear do collide: a ball inside a hull proves it cheaply.
        place(icentres, ijoint, rot, pos, iworld)
        for o in range(len(oradius)):
            if out[k] == COLLIDES:
                break
            for b in range(len(okind)):
                if not (check[o, b] and osolid[b]):
                    continue
                if gap(okind[b], opos[b], orot[b], osize[b], owc[o], oradius[o]) > 0.0:
                    continue
                for s in range(istart[o], istart[o + 1]):
                    if gap(okind[b], opos[b], orot[b], osize[b], iworld[s], iradii[s]) < 0.0:
                        out[k] = COLLIDES
                        break
                if out[k] == COLLIDES:
                    break
        for i in range(len(pairs)):
            if out[k] == COLLIDES:
                break
            a, b = pairs[i, 0], pairs[i, 1]
            if balls_touch(iworld, iradii, (istart[a], istart[a + 1]), (istart[b], istart[b + 1]), True):
                out[k] = COLLIDES
        if stop and out[k] == COLLIDES:
            return k + 1
    return len(qs)
