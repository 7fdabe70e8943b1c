"""Map moveplan errors to one line on stderr (or a JSON document) and the documented exit code.

Also what happens to the process as a whole: output paths checked before any work
(`check_outputs`), SIGTERM and SIGHUP handled like Ctrl-C (`handle_signals`), and a
reader that closes stdout early (`moveplan inspect F | head -1`, `GuardedGroup`).
"""

from __future__ import annotations

import json
import logging
import os
import signal
import sys
import traceback
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager, suppress
from pathlib import Path
from types import FrameType
from typing import Any, NoReturn

import typer
from typer.core import TyperGroup

try:  # typer 0.28 parses with its own copy of click
    from typer._click.exceptions import UsageError as ClickUsageError
except ImportError:
    from click import UsageError as ClickUsageError  # type: ignore[assignment]  # an older typer: click's own

from ..core.errors import MoveplanError, UsageError
from .tables import escape_controls

__all__ = [
    "PIPE_CLOSED", "GuardedGroup", "Interrupted", "all_or_none", "check_outputs", "description_inputs", "exit_codes",
    "handle_signals",
]

logger = logging.getLogger("moveplan")

PIPE_CLOSED = 128 + signal.SIGPIPE
"""Exit code when the reader of stdout or stderr went away: 141, as for a process killed by SIGPIPE."""

_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
_QUIET = "moveplan.quiet"  # ctx.meta key: the command's arguments hold --quiet


class Interrupted(KeyboardInterrupt):
    """SIGINT, SIGTERM or SIGHUP, raised where the program was, so that files being written are cleaned up."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


def handle_signals() -> None:
    """Make SIGINT, SIGTERM and SIGHUP raise Interrupted (exit 128 + signal); ignored signals stay ignored."""
    for signum in _SIGNALS:
        if signal.getsignal(signum) is not signal.SIG_IGN:  # nohup, or a background job's SIGINT
            signal.signal(signum, _interrupt)


def _interrupt(signum: int, _frame: FrameType | None) -> None:
    for other in _SIGNALS:  # one clean-up: a second signal must not cut it short
        signal.signal(other, signal.SIG_IGN)
    raise Interrupted(signum)


def _interrupt_message(exc: KeyboardInterrupt) -> tuple[int, str]:
    signum = getattr(exc, "signum", signal.SIGINT)
    name = "" if signum == signal.SIGINT else f" ({signal.Signals(signum).name})"
    return 128 + signum, f"interrupted{name}"


class GuardedGroup(TyperGroup):
    """The app's command group: a closed stdout exits PIPE_CLOSED quietly, an interrupt 128 + signal.

    Around the whole command, rendering included (exit_codes covers only the work). With --quiet,
    a usage error is one line too, without click's usage text.
    """

    def resolve_command(self, ctx: Any, args: list[str]) -> Any:
        """Return the command `args` name, as click does, noting whether they ask for --quiet."""
        ctx.meta[_QUIET] = "--quiet" in args or "-q" in args
        return super().resolve_command(ctx, args)

    def make_context(self, info_name: str | None, args: list[str], parent: Any = None, **extra: Any) -> Any:
        """Parse the app's own options, as click does; --help or --version meeting a closed or full stdout too."""
        with _output_guarded():
            try:
                return super().make_context(info_name, args, parent, **extra)
            except ClickUsageError as exc:
                _usage_error(exc, quiet=False)

    def invoke(self, ctx: Any) -> Any:
        """Invoke the command; then flush stdout, so that a closed pipe is noticed here, not at exit."""
        with _output_guarded():
            try:
                try:
                    return super().invoke(ctx)
                finally:
                    if sys.stdout is not None:  # None when started with stdout closed
                        sys.stdout.flush()
            except ClickUsageError as exc:
                _usage_error(exc, quiet=bool(ctx.meta.get(_QUIET)))


def _usage_error(exc: ClickUsageError, quiet: bool) -> NoReturn:
    """Exit with click's usage error code, after click's usage text (one line with --quiet) on stderr."""
    if quiet:
        _say(f"moveplan: error: {exc.format_message()}")
    else:
        try:
            exc.show()
        except OSError:  # stderr full or gone: the exit code alone tells
            _to_devnull(2)
    raise typer.Exit(exc.exit_code) from None


@contextmanager
def _output_guarded() -> Iterator[None]:
    """Exit PIPE_CLOSED on a closed stdout, 3 on one that cannot be written, 128 + signal on an interrupt."""
    try:
        yield
    except BrokenPipeError:
        _pipe_closed()
    except SystemExit as exc:
        # rich's Console.on_broken_pipe exits 1 while handling the BrokenPipeError: same case.
        if isinstance(exc.__context__, BrokenPipeError):
            _pipe_closed()
        raise
    except KeyboardInterrupt as exc:
        code, message = _interrupt_message(exc)
        _say(f"moveplan: error: {message}")
        raise typer.Exit(code) from None
    except OSError as exc:
        # The work's errors are turned into exit codes inside the command (exit_codes): what
        # arrives here failed writing stdout (/dev/full, a full disk under `> file`).
        _stdout_failed(exc)


def _stdout_failed(exc: OSError) -> None:
    """Exit 3 with one line on stderr: stdout could not be written; later writes to it are dropped."""
    _to_devnull(1)
    _say(f"moveplan: error: cannot write to standard output: {exc.strerror or exc}")
    raise typer.Exit(3) from None


def _pipe_closed() -> None:
    """Exit PIPE_CLOSED, quietly: later writes (the interpreter's last flush too) go to /dev/null."""
    _to_devnull(1, 2)
    raise typer.Exit(PIPE_CLOSED) from None


def _say(line: str) -> None:
    """Print `line` on stderr; return None.

    A stderr that is closed, full or gone is nowhere to say it: the exit code alone tells, and
    later writes to stderr (the interpreter's last flush too) go to /dev/null.
    """
    if sys.stderr is None:  # started with stderr closed: print(file=None) would write to stdout
        return
    try:
        print(line, file=sys.stderr, flush=True)
    except OSError:
        _to_devnull(2)


def _to_devnull(*descriptors: int) -> None:
    """Point the file descriptors at /dev/null; return None."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    for descriptor in descriptors:
        os.dup2(devnull, descriptor)
    os.close(devnull)


def check_outputs(outputs: Mapping[str, Path | None], inputs: Mapping[str, Path | Sequence[Path] | None]) -> None:
    """Refuse output paths before any work is done; return None.

    `outputs` maps a flag (-o, --csv) to the path given, `inputs` an argument or flag to the
    file(s) the command reads. An output may not be an input (writing it would replace
    it), another output, a directory, a symbolic link, or a device or special file.

    Raises:
        UsageError: Naming the flag, the path and why.

    """
    from ..core.bag import output_problem

    read = [(name, p) for name, given in inputs.items() if given is not None
            for p in ([given] if isinstance(given, Path) else given)]
    seen: dict[str, str] = {}
    for flag, path in outputs.items():
        if path is None:
            continue
        problem = output_problem(path)
        if problem:
            raise UsageError(f"{flag} '{path}': {problem}")
        for name, source in read:
            if _same_file(path, source):
                raise UsageError(f"{flag} '{path}': is also {name}, read by this command; "
                                 "an output must not replace an input")
        where = os.path.realpath(path)
        if where in seen:
            raise UsageError(f"{flag} '{path}': is also {seen[where]}; name two different files")
        seen[where] = flag


@contextmanager
def all_or_none() -> Iterator[list[Path]]:
    """Yield a list to note each output in once written; if the block then fails, those noted are removed.

    For a command writing several files one after the other (benchmark --csv and --plot): each is
    written atomically, but a failure or a signal on the second must not leave the first.
    """
    written: list[Path] = []
    try:
        yield written
    except BaseException:
        for path in written:
            with suppress(OSError):
                path.unlink()
        raise


def description_inputs(urdf: str | None, srdf: str | None, joint_limits: str | None = None) -> dict[str, Path]:
    """Return --urdf, --srdf and --joint-limits as inputs for check_outputs: those naming a file (not a URI)."""
    return {flag: Path(value) for flag, value in (("--urdf", urdf), ("--srdf", srdf), ("--joint-limits", joint_limits))
            if value is not None and "://" not in value}


def _same_file(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist (yet)
        return False


@contextmanager
def exit_codes(as_json: bool, report: Callable[[MoveplanError], dict[str, Any]] | None = None) -> Iterator[None]:
    """Turn a MoveplanError into its exit code and an unexpected exception into exit 1, no traceback.

    `report` returns what the command's JSON document adds to the error's (a plan's steps).
    """
    try:
        yield
    except MoveplanError as exc:
        _report(exc.exit_code, str(exc), as_json, kind=exc.kind, **(report(exc) if report and as_json else {}))
    except KeyboardInterrupt as exc:  # Ctrl-C, and SIGTERM/SIGHUP once handle_signals ran
        _report(*_interrupt_message(exc), as_json, kind="Interrupted")
    except BrokenPipeError:
        raise  # stdout or stderr closed: GuardedGroup exits quietly
    except OSError as exc:
        if exc.filename is None:
            _report(1, _internal(exc), as_json, kind="InternalError")
        # A path the system refuses to look at (too long a name, a loop of links): bad input, named.
        name = str(exc.filename)
        name = name if len(name) <= 120 else f"{name[:60]}...{name[-40:]}"
        _report(3, f"{name}: cannot use it: {exc.strerror or exc}", as_json, kind="InputError")
    except Exception as exc:  # noqa: BLE001 - the last line of defence: a bug must still exit cleanly
        _report(1, _internal(exc), as_json, kind="InternalError")


def _internal(exc: BaseException) -> str:
    """Return the one line describing an unexpected exception (a bug), logged with its traceback at debug."""
    logger.debug("internal error", exc_info=exc)
    detail = traceback.extract_tb(exc.__traceback__)[-1]
    return (f"internal error (a bug in moveplan, please report it): {type(exc).__name__}: {exc} "
            f"[{detail.filename.rsplit('/', 1)[-1]}:{detail.lineno}]")


def _report(code: int, message: str, as_json: bool, *, kind: str, **context: Any) -> None:
    message = escape_controls(message)
    if as_json:
        from ..core.pipeline import failure_document

        print(json.dumps(failure_document(code, kind, message, context)))
    else:
        _say(f"moveplan: error: {message}")
    raise typer.Exit(code)
