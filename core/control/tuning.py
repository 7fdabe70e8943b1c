"""PID gains tuned joint by joint on the simulated plant, by the excavator notes' procedure.

All gains zero; raise P until a disturbance response oscillates steadily; raise D until the
oscillation is critically damped; repeat (P up, D up) until more D no longer helps; then raise
I until the joint reaches the setpoint with the oscillations wanted (usually none). Each
response is a bump of the joint at rest (responses.py), every rung of a ladder of gains
simulated in one pass. docs/execution.md says how each stage decides, and how the procedure
adapts to the velocity and effort interfaces.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from .plants import Response, measure, simulate_responses

__all__ = ["BANDWIDTH_PER_RATE", "Gains", "JointSetup", "JointTuning", "Stage", "tune_joint"]

BANDWIDTH_PER_RATE = 0.3
"""P is never raised past a loop bandwidth of this many [rad]/[s] per [Hz] of update rate (about 5 % of the rate in
Hz, within the rule of thumb of a tenth; 0.1 left 100-150 ms hydraulic drives too slow for MoveIt's start check)."""
STEP = 1.5
"""Ratio between successive rungs of a gain ladder."""
STEADY_DECAY = 0.8
"""A response whose half-cycle peaks shrink by less than this ratio oscillates steadily..."""
STEADY_OSCILLATIONS = 4
"""...once its error has changed sign at least this often."""
FASTER = 0.9
"""Stage 3 goes on while the settling time drops below this fraction of the last one."""
_RUNGS = 24
_BACK_OFFS = 16


@dataclass(frozen=True)
class Gains:
    """One joint's PID gains as JTC reads them (gains.<joint> in ros2_controllers.yaml)."""

    p: float = 0.0
    i: float = 0.0
    d: float = 0.0
    i_clamp: float = 0.0
    ff_velocity_scale: float = 0.0

    def as_dict(self) -> dict[str, float]:
        """Return the gains by ros2_controllers.yaml key."""
        return {"p": self.p, "i": self.i, "d": self.d, "i_clamp": self.i_clamp,
                "ff_velocity_scale": self.ff_velocity_scale}


@dataclass(frozen=True)
class JointSetup:
    """What one joint is tuned on.

    Attributes:
        joint: Its name.
        interface: velocity or effort, the interface JTC's PID adapter drives.
        dt: Control period [s].
        goal_tolerance: Its goal tolerance [rad] (0: not checked).
        plant: pid's plant parameters for this joint (plants.pid_parameters).
        oscillations: Oscillations wanted in stage 4's response.
        window_s: How long each response is simulated [s].
        seed: Seeds the plant's measurement noise.
    """

    joint: str
    interface: str
    dt: float
    goal_tolerance: float
    plant: Mapping[str, float]
    oscillations: int = 0
    window_s: float = 2.0
    seed: int = 0

    @property
    def bump(self) -> float:
        """Return the disturbance [rad]: ten goal tolerances, within [0.005, 0.1] (0.05 unchecked)."""
        if self.goal_tolerance <= 0.0:
            return 0.05
        return min(0.1, max(0.005, 10.0 * self.goal_tolerance))

    @property
    def p_cap(self) -> float:
        """Return the largest P: a loop bandwidth of BANDWIDTH_PER_RATE x the update rate."""
        bandwidth = BANDWIDTH_PER_RATE / self.dt
        return bandwidth if self.interface == "velocity" else self.plant["inertia"] * bandwidth**2


@dataclass(frozen=True)
class Stage:
    """One disturbance response the procedure tried.

    Attributes:
        stage: start, P, D, P down, P+D, I or final.
        gains: The gains it ran with.
        response: What it did.
        chosen: The stage's outcome (the gains carried on), not one of the rungs it passed.
        note: Why it was chosen, for a person.
        trace: Positions relative to the setpoint [rad] per control period, chosen stages only.
    """

    stage: str
    gains: Gains
    response: Response
    chosen: bool = False
    note: str = ""
    trace: NDArray[np.float64] | None = None


@dataclass(frozen=True)
class JointTuning:
    """A joint's tuning: every response tried, in order, and the gains it ends with.

    `load` is the constant load of stage 4's response, in the interface's unit.
    """

    setup: JointSetup
    stages: tuple[Stage, ...]
    gains: Gains
    load: float


def tune_joint(setup: JointSetup, start: Gains) -> JointTuning:
    """Return the joint tuned from `start` (the file's gains, zero gains included)."""
    stages = [_chosen(_run(setup, [start]), "start", "the file's gains")]
    stages += _stage_p(setup, start)
    gains = stages[-1].gains
    damped = _stage_d(setup, gains, "D")
    stages += damped
    stages += _stage_more(setup, damped[-1])
    gains = _last_chosen(stages).gains
    load, tried = _stage_i(setup, gains, start)
    stages += tried
    gains = _last_chosen(stages).gains
    final = _chosen(_run(setup, [gains]), "final", "tuned gains")
    # Only what the stages chose is drawn: the rungs they passed keep their figures alone.
    kept = tuple(s if s.chosen else replace(s, trace=None) for s in (*stages, final))
    return JointTuning(setup, kept, gains, load)


def _stage_p(setup: JointSetup, start: Gains) -> list[Stage]:
    """Return stage 1: P alone raised up the ladder until the response oscillates steadily."""
    cap = setup.p_cap
    low = min(start.p, cap) if start.p > 0.0 else cap * STEP ** -12
    ladder = [low * STEP**k for k in range(_RUNGS) if low * STEP**k < cap * (1 - 1e-9)] + [cap]
    trials = [Gains(p=p, ff_velocity_scale=start.ff_velocity_scale) for p in ladder]
    stages = _run(setup, trials, "P")
    for number, stage in enumerate(stages):
        response = stage.response
        if response.diverged or (response.oscillations >= STEADY_OSCILLATIONS and response.decay_ratio >= STEADY_DECAY):
            return [*stages[:number], _chosen([stage], "P", "oscillates steadily")]
    return [*stages[:-1], _chosen(stages[-1:], "P", "no steady oscillation below the bandwidth limit")]


def _stage_d(setup: JointSetup, gains: Gains, name: str) -> list[Stage]:
    """Return stage 2: D raised until critically damped; P lowered by STEP while no D damps it."""
    tried: list[Stage] = []
    for _ in range(_BACK_OFFS):
        rungs = _run(setup, [replace(gains, d=d) for d in _d_ladder(setup, gains)], name)
        damped = [number for number, stage in enumerate(rungs) if stage.response.damped]
        if damped:
            first = damped[0]
            return [*tried, *rungs[:first], _chosen(rungs[first : first + 1], name, "critically damped")]
        best = min(rungs, key=_badness)
        tried.append(replace(best, stage=name, note="no D damps it: P lowered"))
        gains = replace(gains, p=gains.p / STEP)
        name = "P down"
    rungs = _run(setup, [gains])
    return [*tried, _chosen(rungs, name, "still not damped: lowest P tried")]


def _stage_more(setup: JointSetup, damped: Stage) -> list[Stage]:
    """Return stage 3: P up by STEP and D up again, while that settles faster."""
    stages: list[Stage] = []
    current = damped
    while current.response.damped and current.response.settling_time_s is not None:
        p = current.gains.p * STEP
        if p > setup.p_cap * (1 + 1e-9):
            break
        tried = _stage_d(setup, replace(current.gains, p=p, d=0.0), "P+D")
        better = tried[-1]
        settling = better.response.settling_time_s
        if (better.stage != "P+D" or not better.response.damped or settling is None
                or settling > FASTER * current.response.settling_time_s):
            stages += [replace(s, chosen=False, trace=None) for s in tried]
            stages[-1] = replace(stages[-1], note="no faster: previous gains kept")
            break
        stages += tried
        current = better
    return stages


def _stage_i(setup: JointSetup, gains: Gains, start: Gains) -> tuple[float, list[Stage]]:
    """Return stage 4's load and responses: I raised until the loaded joint reaches the setpoint."""
    load = float(setup.plant.get("load", 0.0))
    if load == 0.0:
        return 0.0, _keep_i(setup, gains, start)
    steady = abs(load) / max(gains.p, 1e-12)
    clamp = max(start.i_clamp, 1.5 * abs(load))
    ladder = [0.0, *(0.02 * gains.p * STEP**k for k in range(_RUNGS))]
    trials = [replace(gains, i=i, i_clamp=clamp if i else gains.i_clamp) for i in ladder]
    positions = simulate_responses(setup.interface, setup.dt, _columns(trials), setup.plant, setup.window_s,
                                   load=load, seed=setup.seed)
    responses = measure(positions, setup.dt, max(steady, setup.bump))
    tolerance = setup.goal_tolerance if setup.goal_tolerance > 0.0 else 0.1 * max(steady, 1e-4)
    stages = [Stage("I", g, r) for g, r in zip(trials, responses, strict=True)]
    for number, (stage, response) in enumerate(zip(stages, responses, strict=True)):
        reached = not response.diverged and abs(response.final_error) <= tolerance
        if reached and response.oscillations <= setup.oscillations:
            note = f"reaches the setpoint under a load of {load:g}"
            return load, [*stages[:number], replace(stage, chosen=True, note=note, trace=positions[:, number])]
    return load, [*stages, replace(stages[0], chosen=True, note="no I reaches the setpoint: I = 0",
                                   trace=positions[:, 0])]


def _keep_i(setup: JointSetup, gains: Gains, start: Gains) -> list[Stage]:
    """Return stage 4 without a load: P alone reaches the setpoint; the file's I stays if it does not ring."""
    i, stages = start.i, list[Stage]()
    for _ in range(_BACK_OFFS):
        if i == 0.0 or start.i_clamp <= 0.0:
            break
        (stage,) = _run(setup, [replace(gains, i=i, i_clamp=start.i_clamp)], "I")
        if stage.response.oscillations <= setup.oscillations and stage.response.damped:
            return [*stages, replace(stage, stage="I", chosen=True, note="the file's I, not ringing (no load)")]
        stages.append(replace(stage, stage="I", note="too many oscillations: I halved"))
        i /= 2.0
    kept = replace(gains, i=0.0, i_clamp=start.i_clamp)
    (stage,) = _run(setup, [kept])
    return [*stages, replace(stage, stage="I", chosen=True, note="no load: P alone reaches the setpoint")]


def _d_ladder(setup: JointSetup, gains: Gains) -> list[float]:
    """Return D rungs from 0 up, scaled to the interface (a critical D is about 2 sqrt(P inertia) through effort)."""
    unit = 0.01 if setup.interface == "velocity" else 0.05 * math.sqrt(gains.p * setup.plant["inertia"])
    return [0.0, *(unit * STEP**k for k in range(_RUNGS))]


def _badness(stage: Stage) -> tuple[bool, float, int]:
    response = stage.response
    return response.diverged, response.overshoot, response.oscillations


def _run(setup: JointSetup, trials: Sequence[Gains], name: str = "") -> list[Stage]:
    """Return the bump responses of `trials` as unchosen stages `name`, carrying their traces."""
    positions = simulate_responses(setup.interface, setup.dt, _columns(trials), setup.plant, setup.window_s,
                                   bump=setup.bump, seed=setup.seed)
    responses = measure(positions, setup.dt, setup.bump)
    return [Stage(name, g, r, trace=positions[:, k]) for k, (g, r) in enumerate(zip(trials, responses, strict=True))]


def _columns(trials: Sequence[Gains]) -> dict[str, NDArray[np.float64]]:
    return {key: np.array([g.as_dict()[key] for g in trials]) for key in Gains().as_dict()}


def _chosen(stages: Sequence[Stage], name: str, note: str) -> Stage:
    return replace(stages[-1], stage=name, chosen=True, note=note)


def _last_chosen(stages: Sequence[Stage]) -> Stage:
    return next(s for s in reversed(stages) if s.chosen)
