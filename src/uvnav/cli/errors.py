"""The CLI's one error path: user errors, bugs and interrupts, handled in :class:`UvnavGroup`.

* A **user error** (bad input: a malformed scenario, an unknown controller, a missing file, a bad
  option) is ONE line ``error: <message>`` on stderr and exit status 2 (or the status the
  :class:`CliError` names).  Commands raise :class:`CliError`; the library's own input errors
  (:class:`~uvnav.scenarios.ScenarioError`, unknown controllers, bad law parameters, missing
  files, click's usage errors) are recognised by :func:`user_error`.
* A **machine error** (a full disk, a read-only file system, a results database SQLite cannot
  write) is ONE line ``error: <message>`` and exit status 74 (``EX_IOERR``): not the input, not a
  bug.  A name too long for the file system is a user error, clipped to one readable line.
* Anything else is a **bug**: it is not disguised as a user error, and no traceback fills the
  screen.  The full traceback goes to a crash log (:func:`crash_log_dir`) and ONE line
  ``internal error: <ExcType>: <message> (traceback in <path>; please report it)`` is printed,
  exit status 70 (``EX_SOFTWARE``).  ``uvnav --debug`` or ``UVNAV_DEBUG=1`` re-raises instead.
* Ctrl-C is exit status 130.
* A closed pipe (``uvnav scenarios list | head``) ends the command quietly, exit status 141, as
  a tool killed by SIGPIPE would.
"""

from __future__ import annotations

import errno
import inspect
import os
import sys
import tempfile
import traceback
from datetime import datetime
from pathlib import Path
from typing import Any

import typer
from typer.core import TyperGroup

from uvnav.validation import clip, one_line

EX_USAGE = 2
"""Exit status of a user error."""
EX_IOERR = 74
"""Exit status when the machine, not the input, stopped the command (a full disk, a read-only
file system), as ``sysexits.h``."""
EX_SOFTWARE = 70
"""Exit status of an internal error (a bug), as ``sysexits.h``."""
EX_INTERRUPTED = 130
"""Exit status after Ctrl-C (128 + SIGINT)."""
EX_PIPE = 141
"""Exit status when the reader of the output went away (128 + SIGPIPE)."""

DEBUG_KEY = "uvnav.debug"
"""``ctx.meta`` key set by the root ``--debug`` option."""


class CliError(Exception):
    """A user-facing error: printed as ``error: <message>``, exit status ``code``."""

    def __init__(self, message: str, code: int = EX_USAGE) -> None:
        super().__init__(message)
        self.message = message
        self.code = code


def _click_classes(exc: BaseException) -> set[str]:
    # Typer vendors click in recent versions; match click's classes by name, not by import path.
    return {
        cls.__name__
        for cls in type(exc).__mro__
        if cls.__module__.split(".")[0] in ("click", "typer")
    }


def is_click_control(exc: BaseException) -> bool:
    """``exc`` is click's own flow control or message (help, exit, abort, usage, bad file)."""
    return bool(_click_classes(exc) & {"Exit", "Abort", "ClickException"})


def user_error(exc: BaseException) -> tuple[str, int] | None:
    """``(one-line message, exit status)`` for an exception caused by the user, else ``None``."""
    from uvnav.controllers import ControllerParamsError, UnknownControllerError
    from uvnav.scenarios import ScenarioError

    if isinstance(exc, CliError):
        return exc.message, exc.code
    if isinstance(exc, ScenarioError):
        return str(exc), EX_USAGE
    if isinstance(exc, UnknownControllerError):
        return str(exc.args[0]) if exc.args else "unknown controller", EX_USAGE
    if isinstance(exc, ControllerParamsError):
        return str(exc), EX_USAGE
    if type(exc).__name__ in ("StaleCampaignError", "NotAStoreError", "ExperimentError"):
        return str(exc), EX_USAGE  # bench.store, uvnav.experiments: not imported here (fast start)
    if isinstance(exc, OSError):
        name = f": {clip(str(exc.filename), 200)}" if exc.filename else ""
        if (
            isinstance(
                exc,
                FileNotFoundError
                | FileExistsError
                | IsADirectoryError
                | NotADirectoryError
                | PermissionError,
            )
            or exc.errno == errno.ENAMETOOLONG
        ):
            return f"{exc.strerror or exc}{name}", EX_USAGE
        if exc.errno in _MACHINE_ERRNOS:
            return f"{exc.strerror or exc}{name}", EX_IOERR
    if type(exc).__module__ == "sqlite3" and any(m in str(exc) for m in _SQLITE_MACHINE):
        return f"results database: {exc}", EX_IOERR
    names = _click_classes(exc)
    if "ClickException" in names and "NoArgsIsHelpError" not in names:
        hint = ""
        ctx = getattr(exc, "ctx", None)
        if "UsageError" in names and ctx is not None:
            hint = f" (see '{ctx.command_path} --help')"
        return f"{exc.format_message()}{hint}", int(getattr(exc, "exit_code", 1))  # type: ignore[attr-defined]
    return None


#: ``errno`` values that say the machine, not the input, stopped the command.
_MACHINE_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EROFS})
#: SQLite's messages for the same (``sqlite3.OperationalError``).
_SQLITE_MACHINE = ("database or disk is full", "attempt to write a readonly database")


def debug_enabled(ctx: Any = None) -> bool:
    """``--debug`` was given on the root command, or ``UVNAV_DEBUG`` is set (not 0/false/no)."""
    if ctx is not None and ctx.meta.get(DEBUG_KEY):
        return True
    return os.environ.get("UVNAV_DEBUG", "").strip().lower() not in ("", "0", "false", "no")


def crash_log_dir() -> Path:
    """Folder of the crash logs: ``$UVNAV_LOG_DIR``, else ``$XDG_STATE_HOME/uvnav``, else
    ``~/.local/state/uvnav``."""
    override = os.environ.get("UVNAV_LOG_DIR")
    if override:
        return Path(override).expanduser()
    state = os.environ.get("XDG_STATE_HOME")
    base = Path(state).expanduser() if state else Path.home() / ".local" / "state"
    return base / "uvnav"


def write_crash_log(exc: BaseException) -> Path | None:
    """Write the command line, versions and the full traceback of ``exc`` to a new file
    ``crash-<timestamp>-<pid>.log`` in :func:`crash_log_dir`, or in the temporary folder when
    that one cannot be written; ``None`` when neither can."""
    from uvnav import __version__

    now = datetime.now()
    stamp = now.strftime("%Y%m%d-%H%M%S")
    text = "".join(
        [
            f"uvnav {__version__} internal error at {now.isoformat(timespec='seconds')}\n",
            f"command: {' '.join(['uvnav', *sys.argv[1:]])}\n",
            f"python {sys.version.split()[0]} on {sys.platform}\n\n",
            *traceback.format_exception(type(exc), exc, exc.__traceback__),
        ]
    )
    for folder in (crash_log_dir(), Path(tempfile.gettempdir()) / "uvnav"):
        try:
            folder.mkdir(parents=True, exist_ok=True)
            path = folder / f"crash-{stamp}-{os.getpid()}.log"
            with path.open("a", encoding="utf-8") as f:
                f.write(text)
            return path
        except OSError:
            continue
    return None


def internal_error_line(exc: BaseException, log: Path | None, limit: int = 300) -> str:
    """The one line printed for a bug."""
    message = one_line(str(exc))
    if len(message) > limit:
        message = message[: limit - 1] + "…"
    what = f"{type(exc).__name__}: {message}" if message else type(exc).__name__
    where = (
        f"traceback in {log}"
        if log is not None
        else "the traceback could not be written; run with --debug to see it"
    )
    return f"internal error: {what} ({where}; please report it)"


def handle(exc: BaseException, ctx: Any = None) -> None:
    """Print the one line for ``exc`` and raise ``typer.Exit`` with its status; re-raise click's
    own flow control (help, exit), and everything under ``--debug``."""
    if isinstance(exc, KeyboardInterrupt):
        typer.echo("interrupted", err=True)
        raise typer.Exit(EX_INTERRUPTED) from None
    if isinstance(exc, BrokenPipeError):  # nothing reads stdout any more: nothing to say
        _stdout_to_devnull()
        raise typer.Exit(EX_PIPE) from None
    handled = user_error(exc)
    if handled is not None:
        message, code = handled
        typer.echo(f"error: {one_line(message)}", err=True)
        raise typer.Exit(code) from None
    if is_click_control(exc) or not isinstance(exc, Exception) or debug_enabled(ctx):
        raise exc
    typer.echo(internal_error_line(exc, write_crash_log(exc)), err=True)
    raise typer.Exit(EX_SOFTWARE) from None


def _stdout_to_devnull() -> None:
    """Point stdout at the null device, so that the flush at exit does not fail again on the
    closed pipe (the recipe of Python's ``signal`` documentation)."""
    try:
        fd = os.open(os.devnull, os.O_WRONLY)
        os.dup2(fd, sys.stdout.fileno())
    except (OSError, ValueError):  # no real stdout (a test runner's buffer): nothing to flush
        pass


def summary(help_text: str | None) -> str:
    """The first paragraph of a command's help, on one line (the command lists' entry)."""
    text = inspect.cleandoc(help_text or "").partition("\f")[0]
    return one_line(text.split("\n\n", 1)[0].replace("\b", ""))


_NO_BREAK_HYPHEN = "\u2011"
# click's classes as Typer vendors them (reached through TyperGroup, not a private import path).
_Context: Any = TyperGroup.context_class
_HelpFormatter: Any = _Context.formatter_class


class HelpFormatter(_HelpFormatter):
    """click's help formatter, but a line never breaks inside a hyphenated word: names such as
    ``random-ch5-dense`` or ``--no-exact-sides`` stay whole at 80 columns."""

    def _whole_words(self, start: int) -> None:
        self.buffer[start:] = [s.replace(_NO_BREAK_HYPHEN, "-") for s in self.buffer[start:]]

    def write_text(self, text: str) -> None:
        start = len(self.buffer)
        super().write_text(text.replace("-", _NO_BREAK_HYPHEN))
        self._whole_words(start)

    def write_dl(self, rows: Any, col_max: int = 30, col_spacing: int = 2) -> None:
        start = len(self.buffer)
        rows = [(a, b.replace("-", _NO_BREAK_HYPHEN)) for a, b in rows]
        super().write_dl(rows, col_max, col_spacing)
        self._whole_words(start)


class HelpContext(_Context):
    """click context whose help uses :class:`HelpFormatter`."""

    formatter_class = HelpFormatter


class UvnavGroup(TyperGroup):
    """Typer group of every ``uvnav`` (sub-)command: the one error path of the module doc, and
    help that reads well at 80 columns (command summaries wrapped, not cut; no line broken
    inside a hyphenated word)."""

    context_class = HelpContext

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        for cmd in self.commands.values():
            if not isinstance(cmd, TyperGroup):
                cmd.context_class = HelpContext

    def make_context(self, info_name: Any, args: Any, parent: Any = None, **extra: Any) -> Any:
        try:
            return super().make_context(info_name, args, parent=parent, **extra)
        except (Exception, KeyboardInterrupt) as exc:
            handle(exc, parent)
            raise  # pragma: no cover  (handle always raises)

    def invoke(self, ctx: Any) -> Any:
        try:
            return super().invoke(ctx)
        except (Exception, KeyboardInterrupt) as exc:
            handle(exc, ctx)
            raise  # pragma: no cover

    def format_commands(self, ctx: Any, formatter: Any) -> None:
        rows = []
        for name in self.list_commands(ctx):
            cmd = self.get_command(ctx, name)
            if cmd is not None and not cmd.hidden:
                rows.append((name, cmd.short_help or summary(cmd.help)))
        if rows:
            with formatter.section("Commands"):
                formatter.write_dl(rows)


def uvnav_typer(**kwargs: Any) -> typer.Typer:
    """A ``typer.Typer`` with the CLI's settings: :class:`UvnavGroup`, help without a command
    shows the help, no completion commands, and help text printed as written (no rich markup,
    so units such as ``[m]`` survive)."""
    kwargs.setdefault("cls", UvnavGroup)
    kwargs.setdefault("no_args_is_help", True)
    kwargs.setdefault("add_completion", False)
    kwargs.setdefault("rich_markup_mode", None)
    kwargs.setdefault("pretty_exceptions_show_locals", False)
    return typer.Typer(**kwargs)
