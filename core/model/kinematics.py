"""Inverse kinematics: the group joint values that put a link at a pose, nearest to the start.

A local Levenberg–Marquardt solve from the start comes first, so a small change
of the target gives a small change of the joints: elbow and wrist stay on the
start's branch. Only if it fails, or its answer collides, do seeded random
restarts run; of the valid solutions they find, the nearest to the start wins
(`exhaustive=True` compares all attempts, the local one included). Revolute
joints whose range exceeds one turn are moved by whole turns to the equivalent
nearest the start.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import eigenpy
import numpy as np
import numpy.typing as npt
import pinocchio as pin
from numpy.typing import NDArray

from ..errors import GoalUnreachable, InputError, SolutionsCollide, UnknownName
from ..types import frozen_array
from .robot import Robot

__all__ = ["IkSolution", "solve_ik"]

_TURN = 2.0 * math.pi
_MAX_ITERATIONS = 80
# Damping in proportion to the squared residual (Sugihara 2011) keeps steps short far from the
# goal and near singularities, and vanishes near a regular solution for quadratic convergence.
# Scale and step length were tuned on the UR10e: 84 % of random poses converge from home.
_DAMPING_SCALE = 0.1
_DAMPING_FLOOR = 1e-6
# [rad] per iteration: caps jumps near singularities (0.3 was slower, 1.5 converged less often).
_MAX_STEP = 0.6
_STALL_ITERATIONS = 8  # without a 2 % gain in that many iterations, it is a local minimum
_VALID_SOLUTIONS = 3  # restarts stop once this many valid solutions compete for the nearest


@dataclass(frozen=True)
class IkSolution:
    """Group joint values reaching a pose, with the residual pose error.

    Attributes:
        values: Group joint values in [rad] or [m], within the joint limits.
        position_error_m: Distance between the reached and target link origin in [m].
        orientation_error_rad: Angle of `R_reached^T R_target` in [rad].
        attempts: Local solves run, the first from the start, the others from random seeds.
    """

    values: NDArray[np.float64]
    position_error_m: float
    orientation_error_rad: float
    attempts: int

    def __post_init__(self) -> None:
        object.__setattr__(self, "values", frozen_array(self.values, (None,), "values"))


def solve_ik(
    robot: Robot,
    target: npt.ArrayLike,
    link: str,
    start: npt.ArrayLike,
    base: NDArray[np.float64] | None = None,
    is_free: Callable[[NDArray[np.float64]], bool] | None = None,
    seed: int = 0,
    max_attempts: int = 40,
    position_tolerance: float = 1e-4,
    orientation_tolerance: float = 1e-3,
    colliding_pair: Callable[[NDArray[np.float64]], tuple[str, str] | None] | None = None,
    exhaustive: bool = False,
    also: Sequence[tuple[str, npt.ArrayLike]] = (),
) -> IkSolution:
    """Return the valid group values nearest to `start` that put `link` at `target` (root_T_link).

    Args:
        robot: The robot and its planning group.
        target: Pose of `link` in the URDF root frame, 4x4 homogeneous, in [m].
        link: Link or frame of the robot model to place.
        start: Current group values; the first initial guess and the reference for "nearest".
        base: Full pinocchio configuration holding the joints outside the group
            (default `robot.neutral()`).
        is_free: Whether group values are collision-free (None: no collision check).
        seed: Seed of the random restarts.
        max_attempts: Local solves at most, the one from `start` included.
        position_tolerance: Largest accepted position error in [m].
        orientation_tolerance: Largest accepted orientation error in [rad]; `math.inf` leaves
            the orientation free (a position goal: only the link origin is placed).
        colliding_pair: Names a colliding pair in a full configuration, for the error message
            (e.g. `CollisionChecker.colliding_pair`).
        exhaustive: Run all `max_attempts` and return the nearest valid solution of them all
            (slower). By default a valid local solution from `start` is returned at once, and
            restarts stop after a few valid solutions.
        also: Further (link, target) pairs to place at the same time, each within the
            tolerances (MoveIt's pose targets for several end-effectors); the errors
            reported are the worst of all.

    Raises:
        GoalUnreachable: No valid solution was found; the message gives the closest pose
            error reached, or says that every solution found collides.
    """
    solver = _solver(robot)
    frame, root_T_target, reference, base = _checked_inputs(robot, solver, target, link, start, base)
    goals = [(frame, root_T_target)]
    for other, other_target in also:
        goals.append(_checked_inputs(robot, solver, other_target, other, start, base)[:2])
    # Converging to half the tolerance leaves margin for callers that re-measure the pose
    # with other arithmetic (arccos of the trace loses digits near zero).
    tolerances = (0.5 * position_tolerance, 0.5 * orientation_tolerance)
    outcome = _search(solver, reference, base, tuple(goals), tolerances, is_free, seed, max_attempts, exhaustive)
    if outcome.best is not None:
        best = outcome.best
        return IkSolution(best.values, best.position_m, best.angle_rad, outcome.attempts)
    raise _unreachable(robot, solver, outcome, link, root_T_target, reference, base, colliding_pair,
                       orientation_tolerance)


def _checked_inputs(
    robot: Robot, solver: _Solver, target: npt.ArrayLike, link: str, start: npt.ArrayLike,
    base: NDArray[np.float64] | None,
) -> tuple[int, pin.SE3, NDArray[np.float64], NDArray[np.float64]]:
    """Return the frame id of `link`, `root_T_target`, the start values and the base configuration, checked."""
    if not robot.model.existFrame(link):
        raise UnknownName("link", link, str(robot.config.urdf_path), robot.link_names)
    frame = robot.model.getFrameId(link)
    root_T_target = _rigid(target, link)
    reference = frozen_array(start, (robot.dof,), "start")
    if not math.isfinite(reference.sum()):
        raise InputError(f"IK start values are not finite: {reference.tolist()}")
    base = solver.neutral if base is None else np.asarray(base, dtype=float)
    if base.shape != solver.neutral.shape:
        raise InputError(f"IK base configuration: expected shape {solver.neutral.shape}, "
                         f"got {base.shape}")
    return frame, root_T_target, reference, base


@dataclass
class _Outcome:
    """What the local solve and the restarts found."""

    best: _Attempt | None = None  # the valid solution nearest the start
    closest: _Attempt | None = None  # of the attempts that did not converge
    colliding: list[NDArray[np.float64]] = field(default_factory=list)  # converged, but not free
    attempts: int = 0


def _search(
    solver: _Solver, reference: NDArray[np.float64], base: NDArray[np.float64], goals: tuple[tuple[int, pin.SE3], ...],
    tolerances: tuple[float, float], is_free: Callable[[NDArray[np.float64]], bool] | None, seed: int,
    max_attempts: int, exhaustive: bool,
) -> _Outcome:
    """Return what the local solve from `reference`, then seeded restarts if needed, found."""
    found = _Outcome()
    rng: np.random.Generator | None = None
    valid = attempts = 0
    while attempts < max(1, max_attempts):
        if attempts == 0:
            guess = np.maximum(np.minimum(reference, solver.clamp_upper), solver.clamp_lower)
        else:
            rng = rng or np.random.default_rng(seed)
            guess = solver.random_guess(rng, reference)
        attempts += 1
        attempt = solver.descend(guess, base, goals, tolerances)
        if not attempt.converged:
            if found.closest is None or attempt.residual < found.closest.residual:
                found.closest = attempt
            continue
        values = solver.nearest_turn(attempt.values, reference)
        if is_free is not None and not is_free(values):
            found.colliding.append(values)
            continue
        valid += 1
        distance = solver.distance(values, reference)
        if found.best is None or distance < found.best.distance:
            found.best = _Attempt(values, attempt.position_m, attempt.angle_rad, attempt.residual, True,
                                  distance)
        if not exhaustive and (attempts == 1 or valid >= _VALID_SOLUTIONS):
            break  # the local solution from the start moves least; restarts gather a few to compare
    found.attempts = attempts
    return found


def _unreachable(
    robot: Robot, solver: _Solver, outcome: _Outcome, link: str, root_T_target: pin.SE3,
    reference: NDArray[np.float64], base: NDArray[np.float64],
    colliding_pair: Callable[[NDArray[np.float64]], tuple[str, str] | None] | None, orientation_tolerance: float,
) -> GoalUnreachable:
    """Return the error for a search with no valid solution: the closest pose error, or what the solutions hit.

    With an infinite `orientation_tolerance` [rad] the orientation is free: the message gives distance only.
    """
    x, y, z = root_T_target.translation
    where = f"no IK solution for link '{link}' at [{x:.3f} {y:.3f} {z:.3f}]"
    attempts, colliding, closest = outcome.attempts, outcome.colliding, outcome.closest
    tries = f"after {attempts} attempt{'s' if attempts != 1 else ''}"
    if colliding:
        count = len(colliding)
        text = f"{where}: " + (f"all {count} solutions found collide" if count > 1
                               else "the solution found collides")
        if colliding_pair is not None:
            nearest = min(colliding, key=lambda values: solver.distance(values, reference))
            pair = colliding_pair(robot.configuration(nearest, base))
            text += f" (nearest the start: {pair[0]} touches {pair[1]})" if pair else ""
        return SolutionsCollide(f"{text} {tries}")
    assert closest is not None  # no attempt converged, so every one was a candidate
    angle = "" if math.isinf(orientation_tolerance) else f", {closest.angle_rad:.3g} rad"
    return GoalUnreachable(f"{where}: closest reached {closest.position_m * 1e3:.1f} mm{angle} away {tries}")


@dataclass(frozen=True)
class _Attempt:
    """Where one local solve ended."""

    values: NDArray[np.float64]
    position_m: float
    angle_rad: float
    residual: float  # hypot(position_m, angle_rad), mixed units: ranks attempts that failed
    converged: bool
    distance: float = math.inf  # from the start, in joint space


class _Solver:
    """Per-robot arrays and pinocchio data for the descent, built once; not thread-safe."""

    def __init__(self, robot: Robot) -> None:
        model = robot.model
        self.model = model
        self.data = model.createData()  # its own: an is_free callback may reuse robot.data
        self.neutral = robot.neutral()
        self.neutral.setflags(write=False)
        self.dof = robot.dof
        self.lower = np.array(robot.lower)
        self.upper = np.array(robot.upper)
        self.continuous = np.array(robot.continuous, dtype=bool)
        # A continuous joint turns freely: clamping it at +-pi would stop the descent there.
        self.clamp_lower = np.where(self.continuous, -np.inf, self.lower)
        self.clamp_upper = np.where(self.continuous, np.inf, self.upper)
        ids = [model.getJointId(name) for name in robot.joint_names]
        self.v_index = np.array([model.idx_vs[i] for i in ids])
        self.q_index = np.array([model.idx_qs[i] for i in ids])
        self.any_continuous = bool(self.continuous.any())
        # Joints that follow a group joint: set with it, and their Jacobian column added to its column.
        self.mimics = [(m.leader, m.q_index, int(model.idx_vs[model.getJointId(m.joint)]), m.multiplier, m.offset)
                       for m in robot.mimics]
        self.all_columns = model.nv == self.dof and bool(
            np.all(self.v_index == np.arange(self.dof)))
        revolute = np.array([model.joints[i].shortname().startswith("JointModelR") for i in ids])
        self.multiturn = revolute & ~self.continuous & (self.upper - self.lower > _TURN)
        self.wraps = self.multiturn | self.continuous
        self.multiturn_limits = [(int(i), float(self.lower[i]), float(self.upper[i]))
                                 for i in np.flatnonzero(self.multiturn)]
        self.normal = np.zeros((self.dof, self.dof))
        self.diagonal = self.normal.reshape(-1)[:: self.dof + 1]  # a view: damping adds in place
        # eigenpy's LLT, allocated once, solves the 6x6 system in ~1 us; np.linalg.solve takes ~11.
        self.cholesky = eigenpy.LLT(self.dof)

    def set_values(self, q: NDArray[np.float64], values: NDArray[np.float64]) -> None:
        """Write group values (and the mimic joints following them) into the full configuration `q` in place."""
        for leader, index, _, multiplier, offset in self.mimics:
            q[index] = multiplier * values[leader] + offset
        if not self.any_continuous:
            q[self.q_index] = values
            return
        plain, cont = ~self.continuous, self.continuous
        q[self.q_index[plain]] = values[plain]
        q[self.q_index[cont]] = np.cos(values[cont])
        q[self.q_index[cont] + 1] = np.sin(values[cont])

    def descend(
        self,
        guess: NDArray[np.float64],
        base: NDArray[np.float64],
        goals: tuple[tuple[int, pin.SE3], ...],
        tolerances: tuple[float, float],
    ) -> _Attempt:
        """Return where damped least squares on the SE3 log errors of `goals` (frame, target) ends, from `guess`.

        With an infinite orientation tolerance, only the position errors and the Jacobians'
        linear rows count: the orientation is free. Several goals stack their errors and Jacobians.
        """
        model, data = self.model, self.data
        position_tolerance2, angle_tolerance2 = tolerances[0] ** 2, tolerances[1] ** 2
        position_only = math.isinf(tolerances[1])
        lower, upper = self.clamp_lower, self.clamp_upper
        normal, diagonal, cholesky = self.normal, self.diagonal, self.cholesky
        values = guess.copy()
        q = base.copy()
        best_residual, best_iteration = math.inf, 0
        position2 = angle2 = math.inf
        for iteration in range(_MAX_ITERATIONS):
            self.set_values(q, values)
            # computeFrameJacobian would leave data.oMf stale; computeJointJacobians runs the
            # forward kinematics too.
            pin.computeJointJacobians(model, data, q)
            if len(goals) == 1:
                error, jacobian, position2, angle2 = self._frame_error(*goals[0], position_only)
            else:
                parts = [self._frame_error(frame, target, position_only) for frame, target in goals]
                error, jacobian = np.concatenate([p[0] for p in parts]), np.vstack([p[1] for p in parts])
                position2, angle2 = max(p[2] for p in parts), max(p[3] for p in parts)
            if position2 <= position_tolerance2 and angle2 <= angle_tolerance2:
                break
            residual = error.dot(error)
            if residual < 0.98 * best_residual:
                best_residual, best_iteration = residual, iteration
            elif iteration - best_iteration >= _STALL_ITERATIONS:
                break
            if not self.all_columns:
                full, jacobian = jacobian, jacobian[:, self.v_index]
                for leader, _, column, multiplier, _ in self.mimics:
                    jacobian[:, leader] += multiplier * full[:, column]
            np.dot(jacobian.T, jacobian, out=normal)
            diagonal += _DAMPING_SCALE * residual + _DAMPING_FLOOR
            cholesky.compute(normal)
            step = cholesky.solve(jacobian.T.dot(error))
            length2 = step.dot(step)
            if length2 > _MAX_STEP**2:
                step *= _MAX_STEP / math.sqrt(length2)
            values += step
            np.minimum(values, upper, out=values)
            np.maximum(values, lower, out=values)
        position, angle = math.sqrt(position2), math.sqrt(angle2)
        converged = position <= tolerances[0] and angle <= tolerances[1]
        return _Attempt(values, position, angle, math.sqrt(position2 + (0.0 if position_only else angle2)), converged)

    def _frame_error(
        self, frame: int, target: pin.SE3, position_only: bool,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], float, float]:
        """Return (error, Jacobian, squared position error, squared angle) of one frame, after the kinematics.

        LOCAL: the Jacobian maps joint velocities to the link's twist in its own frame, the frame
        of log6(root_T_link^-1 root_T_target); position only, its linear rows and the translation.
        """
        model, data = self.model, self.data
        jacobian = pin.getFrameJacobian(model, data, frame, pin.LOCAL)
        link_T_target = pin.updateFramePlacement(model, data, frame).actInv(target)
        error = pin.log6(link_T_target).vector
        translation = link_T_target.translation
        angle2 = error[3:].dot(error[3:])
        if position_only:
            return translation, jacobian[:3], translation.dot(translation), angle2
        return error, jacobian, translation.dot(translation), angle2

    def random_guess(
        self, rng: np.random.Generator, start: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """Return a uniform guess within the limits, and within a turn about `start` where wider."""
        # Every angle has one equivalent in a one-turn window; keep the window around the start,
        # moved inside the limits, so the seed does not add a needless turn.
        window = np.clip(start - math.pi, self.lower, self.upper - _TURN)
        low = np.where(self.multiturn, window, self.lower)
        low = np.where(self.continuous, start - math.pi, low)
        high = np.where(self.wraps, low + _TURN, self.upper)
        return rng.uniform(low, high)

    def nearest_turn(
        self, values: NDArray[np.float64], start: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """Return `values` with multi-turn joints moved by whole turns to the nearest to `start`."""
        # Plain floats: numpy's per-call overhead would cost more than the arithmetic.
        out, reference = values.tolist(), start.tolist()
        for i, lower, upper in self.multiturn_limits:
            nearest = out[i] + _TURN * round((reference[i] - out[i]) / _TURN)
            # Past a limit, the next turn inwards is the nearest equivalent within the limits.
            if nearest > upper:
                nearest -= _TURN
            elif nearest < lower:
                nearest += _TURN
            if lower <= nearest <= upper:
                out[i] = nearest
        turned = np.array(out)
        if self.any_continuous:
            wrapped = np.remainder(turned[self.continuous] + math.pi, _TURN) - math.pi
            turned[self.continuous] = wrapped
        return turned

    def distance(self, values: NDArray[np.float64], start: NDArray[np.float64]) -> float:
        """Return the joint-space distance from `start`, the short way round if continuous."""
        delta = values - start
        if self.any_continuous:
            delta[self.continuous] = np.remainder(delta[self.continuous] + math.pi, _TURN) - math.pi
        return float(math.sqrt(delta.dot(delta)))


_SOLVERS: weakref.WeakKeyDictionary[Robot, _Solver] = weakref.WeakKeyDictionary()


def _solver(robot: Robot) -> _Solver:
    solver = _SOLVERS.get(robot)
    if solver is None:
        solver = _SOLVERS[robot] = _Solver(robot)
    return solver


def _rigid(target: npt.ArrayLike, link: str) -> pin.SE3:
    """Return `target` as an SE3, after checking it is a finite rigid transform."""
    matrix = np.asarray(target, dtype=float)
    if matrix.shape != (4, 4):
        raise InputError(f"target pose for link '{link}': expected a 4x4 matrix, "
                         f"got shape {matrix.shape}")
    (a, b, c, x), (d, e, f, y), (g, h, k, z) = matrix[:3].tolist()
    # Plain floats: numpy's per-call overhead would cost more than the arithmetic.
    deviation = ((a * a + b * b + c * c - 1) ** 2 + (d * d + e * e + f * f - 1) ** 2
                 + (g * g + h * h + k * k - 1) ** 2 + 2 * (a * d + b * e + c * f) ** 2
                 + 2 * (a * g + b * h + c * k) ** 2 + 2 * (d * g + e * h + f * k) ** 2)
    determinant = a * (e * k - f * h) - b * (d * k - f * g) + c * (d * h - e * g)
    # Written so that NaN fails every test.
    if not (deviation < 1e-9 and determinant > 0 and math.isfinite(x + y + z)):
        raise InputError(f"target pose for link '{link}': not a finite rigid transform "
                         "(the rotation part must be orthonormal with determinant +1)")
    return pin.SE3(matrix)
