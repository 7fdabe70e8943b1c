"""`moveplan tune-pid`: PID gains tuned joint by joint on the simulated plant, written and verified."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .errors import check_outputs, exit_codes
from .options import JsonOpt, QuietOpt, StrictOpt, VerboseOpt, setup_logging
from .parsing import MAX_SEED, parse_params

__all__ = ["tune_pid"]


def tune_pid(
    plan_file: Annotated[Path, typer.Argument(metavar="PLAN", help="Plan file written by moveplan plan.")],
    output: Annotated[Path, typer.Option("--output", "-o", help="Controllers file to write, gains tuned (.yaml).")],
    controllers: Annotated[Path | None, typer.Option(help="ros2_controllers.yaml to tune (else the plan's).")] = None,
    joints: Annotated[str | None, typer.Option(help="Joints to tune, comma-separated (default: all).")] = None,
    plant_param: Annotated[list[str] | None, typer.Option(help="pid plant parameter k=v, as for execute.")] = None,
    oscillations: Annotated[int, typer.Option(min=0, help="Oscillations wanted as I is raised (stage 4).")] = 0,
    recording: Annotated[Path | None, typer.Option(
        metavar="REC.mcap", help="The robot following this plan: fit the plant to it first.")] = None,
    topic: Annotated[str, typer.Option(help="JointState topic in --recording.")] = "/joint_states",
    plot: Annotated[Path | None, typer.Option(metavar="FILE.png", help="Write a PNG of the responses.")] = None,
    seed: Annotated[int, typer.Option(min=0, max=MAX_SEED, help="Seed for plant noise.")] = 0,
    strict: StrictOpt = False,
    as_json: JsonOpt = False,
    quiet: QuietOpt = False,
    verbose: VerboseOpt = False,
) -> None:
    """Tune PID gains joint by joint on the simulated pid plant; write them into a copy of the controllers file.

    Exit 0 when executing the plan with the tuned gains passes without a ringing joint, 5 when it does not
    (the file is written either way).
    """
    setup_logging(verbose, quiet)
    with exit_codes(as_json):
        check_outputs({"-o": output, "--plot": plot},
                      {"PLAN": plan_file, "--controllers": controllers, "--recording": recording})
        from ..core.pipeline import TuneRequest, tune, write_tuning_plot
        from .render_tuning import tuning_summary

        if plot is not None:
            from ..core.pipeline import check_plot_path

            check_plot_path(plot)
        names = tuple(j.strip() for j in (joints or "").split(",") if j.strip())
        result = tune(TuneRequest(plan_file, output, controllers, names,
                                  parse_params(plant_param or [], "--plant-param"), oscillations, recording, topic,
                                  seed, plot, strict), write_tuning_plot)
    tuning_summary(result, plot, as_json, quiet)
    raise typer.Exit(0 if result.ok else 5)
