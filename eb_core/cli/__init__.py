"""The ``eb`` command: one module per command (``run``, ``list``, ``report``, ``show``, ``tasks``; ``prompt``,
``export`` and ``audit`` live beside what they drive), dispatched by :func:`main`.

Bad input ends with one line on stderr that says what was wrong, what is allowed and how to fix it: every
command raises :class:`eb_core.exceptions.UserError` (or a component's own error) and only this module prints it.
"""

from __future__ import annotations

import difflib
import signal
import sys
from collections.abc import Callable, Sequence

# Names other modules and tests imported from the single-file CLI; the config path now lives in eb_core.compose.
from eb_core.compose import GROUPS, compose
from eb_core.compose import group_options as _group_options
from eb_core.compose import hydra_context as _hydra_context
from eb_core.compose import validate as _validate
from eb_core.exceptions import CliError, ConfigError, UserError

__all__ = ["CliError", "GROUPS", "USAGE", "compose", "main"]
_COMPAT = (_group_options, _hydra_context, _validate)

USAGE = """usage: eb <command> [args]

commands:
  run [key=value ...]        run a benchmark: -m sweeps (a=x,y), --cfg job prints the config that would run
                             e.g. eb run env=navigation model=oracle limit=10
  list                       installed envs (subsets, task counts, task sets), models, planners, augmenters,
                             metrics and ablations, each with its plugin
  report RUN_DIR [...]       paper-style tables of runs with 95% intervals, ablation deltas and the
                             automatic error analysis [--format rich|markdown|csv|latex|html] [--out FILE]
                             [--plot FILE.png|.svg] [--errors: relabel from the step files, per subset];
                             `report A B --paired`: is B's difference to A real?
  show RUN_DIR [RUN_DIR ...] write RUN_DIR/index.html: every episode, step, image, answer, feedback and
                             error label, with filters; several runs: a side-by-side comparison [--out DIR];
                             --bundle OUT RUN...: a static results site (leaderboards, capabilities, viewers)
  export RUN_DIR --out DIR   planner steps as a dataset [--format parquet|chat] [--images embed|paths]
                             [--only-success]; with a dataset card (README.md); --format video: one replayed,
                             captioned MP4 (or --gif) per episode; RUN... --format matrix: task x run table
  prompt env=NAME task=ID [step=N] [ablation=NAME] [out=DIR]   print what the model receives at planner
                             call N (the expert plays the earlier ones); images saved as PNG beside prompt.txt
  tasks generate env=NAME [key=value ...]   write a task file with the env's generator
  audit env=NAME [task_file=PATH] [--quick] [--probe NAME]   shortcut probes of a task set; exit 1 on a failure
  verify RUN_DIR [...] [--render]   replay every episode from its task, seed and recorded actions (no model)
                             and check the records and manifest; one line per mismatch, exit 1 on any
  plan env=NAME target=width:PTS|diff:PTS [subset=...] [from=RUN]   tasks, repeats and cost a measurement needs
  serve env=NAME [taskset=...] [split=...] [runner.workers=N] [port=...]   the worlds as an HTTP service
"""

COMMANDS = ("run", "list", "report", "show", "export", "prompt", "tasks", "audit", "verify", "plan", "serve")


class Terminated(KeyboardInterrupt):
    """SIGTERM, handled like Ctrl-C: finished episodes are saved and the process exits with one line."""


def _fail(msg: str, code: int = 2) -> int:
    print(f"eb: error: {msg}", file=sys.stderr)
    return code


def _command(cmd: str) -> Callable[[list[str]], int]:
    """The function behind ``eb CMD``, imported only when that command runs."""
    if cmd == "run":
        from eb_core.cli.run import cmd_run

        return cmd_run
    if cmd == "list":
        from eb_core.cli.list import cmd_list

        return cmd_list
    if cmd == "report":
        from eb_core.cli.report import cmd_report

        return cmd_report
    if cmd == "show":
        from eb_core.cli.show import cmd_show

        return cmd_show
    if cmd == "tasks":
        from eb_core.cli.tasks import cmd_tasks

        return cmd_tasks
    if cmd == "prompt":
        from eb_core.prompt_view import cmd_prompt

        return cmd_prompt
    if cmd == "export":
        from eb_core.export import cmd_export

        return cmd_export
    if cmd == "audit":
        from eb_core.audit import cmd_audit

        return cmd_audit
    if cmd == "verify":
        from eb_core.verify import cmd_verify

        return cmd_verify
    if cmd == "plan":
        from eb_core.budget import cmd_plan

        return cmd_plan
    from eb_core.serve.command import main as cmd_serve

    return cmd_serve


def _on_sigterm(signum: int, frame: object) -> None:
    raise Terminated()


def main(argv: Sequence[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    if not args or args[0] in ("-h", "--help", "help"):
        print(USAGE)
        return 0 if args else 2
    cmd, rest = args[0], args[1:]
    if cmd not in COMMANDS:
        hint = difflib.get_close_matches(cmd, COMMANDS, n=1)
        return _fail(f"unknown command {cmd!r}; commands: {', '.join(COMMANDS)}"
                     + (f" (did you mean {hint[0]!r}?)" if hint else ""))
    previous = signal.getsignal(signal.SIGTERM)
    try:
        signal.signal(signal.SIGTERM, _on_sigterm)
    except ValueError:  # not the main thread (main() called from a thread): SIGTERM keeps its handler
        previous = None
    try:
        return _command(cmd)(rest)
    except (UserError, ConfigError) as exc:
        return _fail(str(exc))
    except Terminated:
        return _fail("terminated (SIGTERM); finished episodes are saved, re-run the same command to resume", 143)
    except KeyboardInterrupt:
        return _fail("interrupted; finished episodes are saved, re-run the same command to resume", 130)
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
