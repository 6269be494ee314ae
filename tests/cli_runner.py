"""A ``CliRunner`` for the corpus tests, which invoke the CLI thousands of times."""

from __future__ import annotations

from typing import Any

from typer.testing import CliRunner


class FastRunner(CliRunner):
    """``CliRunner`` that builds the click command of the app once, not on every call (Typer
    rebuilds it from the signatures each time: 80 % of a corpus case's time)."""

    _command: Any = None

    def invoke(self, app: Any, args: Any = None, **kw: Any) -> Any:  # type: ignore[override]
        import typer.main
        import typer.testing

        if FastRunner._command is None:
            FastRunner._command = typer.main.get_command(app)
        original = typer.testing._get_command
        typer.testing._get_command = lambda _app: FastRunner._command  # type: ignore[assignment]
        try:
            return super().invoke(app, args, prog_name="uvnav", **kw)
        finally:
            typer.testing._get_command = original
