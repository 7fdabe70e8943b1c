"""The sphere filter's compiled kernels (numba), at module level so numba caches them on disk.

Compiled ahead of time into an extension module (core/collision/compiled.py, core/_native.py),
or run by numba's JIT where that cannot be built: imported only then, since importing numba
costs a fresh process ~0.3 s. The filter's arrays travel packed in one float and one integer
array (core/collision/_packing.py, `unpack` here); inside, they come in tuples by what they
describe (see SphereFilter).
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from ._verdicts import CLEAR, COLLIDES, MAYBE

# numba caches a kernel by this file's bytes alone; the line below changes them with the sources its
# kernels compile in (tests/foundation/test_kernel_inputs.py says what it must read).
# Compiled in (sha256): collision/_verdicts.py 5c11907276b0

__all__ = ["STRIDE", "classify", "edge", "tabled", "tabled_clearance"]

STRIDE = 8  # an edge's states are judged every STRIDE-th first


@numba.njit(cache=True)
def gap(kind: int, centre: Any, rot: Any, size: Any, p: Any, radius: float) -> float:
    """Return d^2 - radius^2 for a ball at `p` whose centre lies d from an obstacle (box, sphere, cylinder).

    Its sign is that of the gap between ball and obstacle (<= 0: they touch), found without a square root.
    """
    d0, d1, d2 = p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]
    x = rot[0, 0] * d0 + rot[1, 0] * d1 + rot[2, 0] * d2
    y = rot[0, 1] * d0 + rot[1, 1] * d1 + rot[2, 1] * d2
    z = rot[0, 2] * d0 + rot[1, 2] * d1 + rot[2, 2] * d2
    if kind == 0:
        ex = max(abs(x) - size[0], 0.0)
        ey = max(abs(y) - size[1], 0.0)
        ez = max(abs(z) - size[2], 0.0)
        return ex * ex + ey * ey + ez * ez - radius * radius
    if kind == 1:
        return x * x + y * y + z * z - (size[0] + radius) ** 2
    er = max(np.sqrt(x * x + y * y) - size[0], 0.0)
    ez = max(abs(z) - size[1], 0.0)
    return er * er + ez * ez - radius * radius


@numba.njit(cache=True)
def apart(p: Any, r: Any, reach: float) -> bool:
    """Return True if points `p` and `r` are farther apart than `reach`."""
    dx, dy, dz = p[0] - r[0], p[1] - r[1], p[2] - r[2]
    return dx * dx + dy * dy + dz * dz > reach * reach


@numba.njit(cache=True)
def tabled_clearance(q: Any, tables: Any) -> tuple[int, float]:
    """Return the tables' verdict at `q` (see `tabled`) and, if CLEAR, the least tabulated distance less its margin.

    That distance [m] bounds the tabulated pairs' distance at `q` from below: a table's margin
    bounds how far a pair moves between a state and its nearest grid point.
    """
    axes, start, step, count, offset, margin, distance = tables
    verdict, best = CLEAR, np.inf
    for p in range(len(offset)):
        flat = 0
        for axis in range(2):
            if axes[p, axis] < 0:
                continue
            x = (q[axes[p, axis]] - start[p, axis]) / step[p, axis]
            if x < -0.5 or x >= count[p, axis] - 0.5:
                return MAYBE, 0.0  # off the grid, where the margin does not hold
            flat = flat * count[p, axis] + int(x + 0.5)
        d = distance[offset[p] + flat]
        if d < -margin[p]:
            return COLLIDES, 0.0
        if d <= margin[p]:
            verdict = MAYBE
        best = min(best, d - margin[p])
    return verdict, (best if verdict == CLEAR else 0.0)


@numba.njit(cache=True)
def tabled(q: Any, tables: Any) -> int:
    """Return CLEAR if every tabulated pair is apart at `q`, COLLIDES if one surely touches, else MAYBE."""
    return tabled_clearance(q, tables)[0]


@numba.njit(cache=True)
def forward(q: Any, joints: Any, rot: Any, pos: Any, local: Any) -> None:
    """Write every joint's world rotation and position at configuration `q` into `rot`, `pos` (joint 0: world).

    `local` is 3 x 3 scratch.
    """
    parents, kinds, axes, iq, prot, ptrans = joints
    rot[0] = 0.0
    for r in range(3):
        rot[0, r, r] = 1.0
    pos[0] = 0.0
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
def set_mimics(q: Any, values: Any, mimic: Any) -> None:
    """Set each mimic joint of `q` from its leader's group value (core/model/robot.py's Mimic)."""
    index, leader, scale, offset = mimic
    for m in range(len(index)):
        q[index[m]] = scale[m] * values[leader[m]] + offset[m]


@numba.njit(cache=True)
def judge(values: Any, stop: bool, base: Any, group: Any, continuous: Any, model: Any, qs: Any, out: Any) -> int:
    """Write per group state (rows of `values`) its configuration into `qs` and its verdict into `out`.

    Returns how many states were judged: all, or with `stop` up to the first COLLIDES.
    One loop over all states: a function called per state would be passed every array of
    the model each time, which costs more than the judging. Measured: moving its stages into
    @njit helpers, inlined by numba or not, makes classify and edge 9-29 % slower.
    """
    tables, joints, spheres, owners, inner, pairs, obstacles, check, mimic = model
    centres, radii, sjoint, start = spheres
    ojoint, ocentre, oradius = owners
    okind, opos, orot, osize, _, oball = obstacles
    nj = len(joints[0])
    rot, pos = np.empty((nj, 3, 3)), np.empty((nj, 3))
    world, iworld = np.empty((len(radii), 3)), np.empty((len(inner[1]), 3))
    owc, placed = np.empty((len(oradius), 3)), np.empty(len(oradius), dtype=np.bool_)
    near = np.empty(len(radii), dtype=np.int64)
    local = np.empty((3, 3))
    for k in range(len(values)):
        q = qs[k]
        q[:] = base
        for i in range(len(group)):
            if continuous[i]:
                q[group[i]] = np.cos(values[k, i])
                q[group[i] + 1] = np.sin(values[k, i])
            else:
                q[group[i]] = values[k, i]
        set_mimics(q, values[k], mimic)
        verdict = tabled(q, tables)
        if verdict != CLEAR:
            out[k] = verdict
            if stop and verdict == COLLIDES:
                return k + 1
            continue
        forward(q, joints, rot, pos, local)
        place(ocentre, ojoint, rot, pos, owc)
        # An owner's spheres are placed only when something comes within its bounding ball.
        placed[:] = False
        free = True
        for o in range(len(oradius)):
            if not free:
                break
            for b in range(len(okind)):
                if not check[o, b] or apart(owc[o], opos[b], oradius[o] + oball[b]):
                    continue  # the ball around the obstacle first: a fifth of the cost of its exact gap
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
        out[k] = CLEAR if free else _inside(model, rot, pos, iworld, owc)
        if stop and out[k] == COLLIDES:
            return k + 1
    return len(values)


@numba.njit(cache=True, inline="always")
def _inside(model: Any, rot: Any, pos: Any, iworld: Any, owc: Any) -> int:
    """Return COLLIDES if a ball inside a hull touches an obstacle or another owner's inner ball, else MAYBE."""
    _, _, _, owners, inner, pairs, obstacles, check, _ = model
    _, _, oradius = owners
    icentres, iradii, ijoint, istart = inner
    okind, opos, orot, osize, osolid, oball = obstacles
    # Most states the spheres cannot clear do collide: a ball inside a hull proves it cheaply.
    place(icentres, ijoint, rot, pos, iworld)
    for o in range(len(oradius)):
        for b in range(len(okind)):
            if not (check[o, b] and osolid[b]) or apart(owc[o], opos[b], oradius[o] + oball[b]):
                continue
            if gap(okind[b], opos[b], orot[b], osize[b], owc[o], oradius[o]) > 0.0:
                continue
            for s in range(istart[o], istart[o + 1]):
                if gap(okind[b], opos[b], orot[b], osize[b], iworld[s], iradii[s]) < 0.0:
                    return COLLIDES
    for i in range(len(pairs)):
        a, b = pairs[i, 0], pairs[i, 1]
        if balls_touch(iworld, iradii, (istart[a], istart[a + 1]), (istart[b], istart[b + 1]), True):
            return COLLIDES
    return MAYBE


@numba.njit(cache=True)
def classify(values: Any, stop: bool, floats: Any, ints: Any, head: Any, qs: Any, out: Any) -> int:
    """Write per group state (rows of `values`) its configuration into `qs` and its verdict into `out`.

    CLEAR: no sphere touches an obstacle or another owner's sphere, and the tables say
    apart. COLLIDES: a tabulated pair, or a ball inside a hull, surely touches something
    (an obstacle it is checked against, or another owner's inner ball). Else MAYBE.
    Returns how many states were judged: all, or with `stop` up to the first COLLIDES.
    """
    base, group, continuous, model = unpack(floats, ints, head)
    return judge(values, stop, base, group, continuous, model, qs, out)


@numba.njit(cache=True)
def edge(a: Any, b: Any, resolution: float, stop: bool, floats: Any, ints: Any, head: Any, verdicts: Any,
         unclear: Any) -> tuple[int, int]:
    """Judge the states on the straight edge from `a` to `b`; return (worst verdict, how many are not CLEAR).

    The states are a + (b - a) i / n for i = 1..n, no joint moving more than `resolution`
    between two; every STRIDE-th first, since most edges a search tries run into something
    over many states in a row, and those find it with a fraction of the checks. The verdicts
    and configurations of the states not CLEAR go to the front of `verdicts` and `unclear`;
    with `stop`, judging ends at the first that COLLIDES. If those hold fewer than n rows,
    nothing is judged and the count returned is -n.
    """
    base, group, continuous, model = unpack(floats, ints, head)
    count = 1
    for i in range(len(a)):
        count = max(count, int(np.ceil(abs(b[i] - a[i]) / resolution)))
    if count > len(verdicts):
        return CLEAR, -count
    strided = count // STRIDE if count >= 2 * STRIDE else 0
    values = np.empty((count, len(a)))
    for m in range(count):
        if m < strided:
            step = (m + 1) * STRIDE
        elif strided:
            r = m - strided  # the r-th step that is not a multiple of STRIDE
            step = r + r // (STRIDE - 1) + 1
        else:
            step = m + 1
        for i in range(len(a)):
            values[m, i] = a[i] + (b[i] - a[i]) * (step / count)
    qs = np.empty((count, len(base)))
    out = np.empty(count, dtype=np.int8)
    judged = judge(values, stop, base, group, continuous, model, qs, out)
    worst, kept = CLEAR, 0
    for k in range(judged):
        if out[k] != CLEAR:
            worst = min(worst, out[k])
            verdicts[kept] = out[k]
            unclear[kept] = qs[k]
            kept += 1
    return worst, kept


@numba.njit(cache=True)
def _1d(flat: Any, h: Any) -> Any:
    return flat[h[0]:h[0] + h[1]]


@numba.njit(cache=True)
def _2d(flat: Any, h: Any) -> Any:
    return flat[h[0]:h[0] + h[1] * h[2]].reshape((h[1], h[2]))


@numba.njit(cache=True)
def _3d(flat: Any, h: Any) -> Any:
    return flat[h[0]:h[0] + h[1] * h[2] * h[3]].reshape((h[1], h[2], h[3]))


@numba.njit(cache=True)
def unpack(f: Any, i: Any, h: Any) -> Any:
    """Return base, group, continuous and the model tuple that `judge` reads, as views into `pack`'s arrays."""
    tables = (_2d(i, h[3]), _2d(f, h[4]), _2d(f, h[5]), _2d(i, h[6]), _1d(i, h[7]), _1d(f, h[8]), _1d(f, h[9]))
    joints = (_1d(i, h[10]), _1d(i, h[11]), _2d(f, h[12]), _1d(i, h[13]), _3d(f, h[14]), _2d(f, h[15]))
    spheres = (_2d(f, h[16]), _1d(f, h[17]), _1d(i, h[18]), _1d(i, h[19]))
    owners = (_1d(i, h[20]), _2d(f, h[21]), _1d(f, h[22]))
    inner = (_2d(f, h[23]), _1d(f, h[24]), _1d(i, h[25]), _1d(i, h[26]))
    obstacles = (_1d(i, h[28]), _2d(f, h[29]), _3d(f, h[30]), _2d(f, h[31]), _1d(i, h[32]), _1d(f, h[34]))
    mimic = (_1d(i, h[35]), _1d(i, h[36]), _1d(f, h[37]), _1d(f, h[38]))
    model = (tables, joints, spheres, owners, inner, _2d(i, h[27]), obstacles, _2d(i, h[33]), mimic)
    return _1d(f, h[0]), _1d(i, h[1]), _1d(i, h[2]), model
