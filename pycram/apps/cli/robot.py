"""`pycram robot list` and `pycram robot check NAME...`: the registered robots, and a conformance
run for each (:mod:`pycram.apps.robot_check`).

``pycram robot check`` prints one table per robot (check, PASS / FAIL / SKIP, why, simulated and
wall time) and exits with code 1 when a check failed, 2 for bad options (an unknown robot: the
message lists the registered ones), 0 otherwise. ``--short`` runs the short form (description,
world, motions, reach, camera and one action: seconds per robot); ``--json FILE`` also writes
the reports as JSON.
"""

from __future__ import annotations

from pathlib import Path

import typer

from pycram.apps.cli.app import app, console, err, fail

robot_app = typer.Typer(
    name="robot",
    help="The registered robots: list them, check one (a conformance run).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
app.add_typer(robot_app, name="robot")


@robot_app.command("list")
def list_command(
    json_file: Path | None = typer.Option(None, "--json", metavar="FILE", help="Also write the list as JSON to FILE."),
) -> None:
    """The registered robots (the `pycram.robots` entry points): arms with their joint counts
    and tool frames, grippers, base kind, torso range, camera and URDF."""
    import json

    from pycram.apps.robot_check.listing import robot_rows, robots_table

    rows = robot_rows()
    console.print(robots_table(rows))
    if json_file is not None:
        try:
            json_file.write_text(json.dumps([r.as_dict() for r in rows], indent=2) + "\n", encoding="utf-8")
        except OSError as e:
            fail(f"--json {json_file}: cannot write it ({e.strerror or e})", code=2)


@robot_app.command("check")
def check_command(
    names: list[str] = typer.Argument(..., metavar="NAME...", help="The robots to check (registered names)."),
    short: bool = typer.Option(
        False, "--short", help="The short form: description, world, motions, reach, camera and one action."
    ),
    json_file: Path | None = typer.Option(
        None, "--json", metavar="FILE", help="Also write the reports as JSON to FILE (for machines)."
    ),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress lines while the checks run."),
) -> None:
    """A conformance run: the description validates and the world builds, every motion type of
    the vocabulary, each arm's reach envelope, the camera sees a test object, each action of the
    library on a fixed scene, and (full form) set-table on development seeds 0-2.

    Exit code: 0 when every check passed (or was skipped), 1 when one failed, 2 for bad options."""
    import os

    from pycram.world.robot_registry import UnknownRobotError, robot_package

    os.environ.setdefault("MUJOCO_GL", "egl")
    for name in names:
        try:
            robot_package(name)
        except UnknownRobotError as e:
            fail(f"{e}; see `pycram robot list`", code=2)
    if json_file is not None and json_file.parent != Path("") and not json_file.parent.is_dir():
        fail(f"--json {json_file}: the folder {json_file.parent} does not exist", code=2)
    from rich.markup import escape

    from pycram.apps.robot_check import CheckResult, report_table, run_robot_check, write_json
    from pycram.apps.robot_check.report import STYLES

    def finished(result: CheckResult) -> None:
        if not quiet:
            err.print(
                f"  [{STYLES[result.result]}]{result.result}[/] {escape(result.check)} ({result.wall_time:.1f} s)"
            )

    reports = []
    for name in names:
        if not quiet:
            err.print(f"checking {name} ({'short' if short else 'full'} form)")
        reports.append(run_robot_check(name, short=short, on_result=finished))
        console.print(report_table(reports[-1]))
    if json_file is not None:
        try:
            write_json(reports, json_file)
        except OSError as e:
            fail(f"--json {json_file}: cannot write it ({e.strerror or e})", code=2)
    failed = [r.robot for r in reports if not r.passed]
    if failed:
        err.print(f"[bold red]failed:[/] {', '.join(failed)}")
        raise typer.Exit(1)
