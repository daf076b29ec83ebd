"""``eb show RUN_DIR [RUN_DIR ...]``: the static HTML viewer of one run, or a comparison of several."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import NoReturn

from eb_core.exceptions import CliError

USAGE = ("usage: eb show RUN_DIR (a directory holding episodes.jsonl), or eb show RUN_A RUN_B ... [--out DIR], "
         "or eb show --bundle OUT RUN...")


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:  # one line, raised instead of exit(2)
        raise CliError(f"show: {message}; {USAGE}")


def cmd_show(args: list[str]) -> int:
    from eb_core.html import write_compare, write_html

    p = _Parser(prog="eb show", add_help=False, allow_abbrev=False)
    p.add_argument("dirs", nargs="*")
    p.add_argument("--out")
    p.add_argument("--bundle")
    ns = p.parse_args(args)
    if ns.out == "":
        raise CliError(f"--out needs a directory; {USAGE}")
    if ns.bundle == "":
        raise CliError(f"--bundle needs a new folder; {USAGE}")
    if not ns.dirs:
        raise CliError(USAGE)
    for d in ns.dirs:
        if not (Path(d) / "episodes.jsonl").exists():
            raise CliError(f"{d} is not a run directory (no episodes.jsonl)")
    if ns.bundle is not None:
        from eb_core.bundle import write_bundle

        try:
            print(write_bundle(ns.dirs, ns.bundle))
        except (FileExistsError, ValueError) as exc:
            raise CliError(str(exc)) from None
        return 0
    if len(ns.dirs) == 1:
        if ns.out:
            raise CliError("--out is for comparing several runs; one run's viewer is written into RUN_DIR")
        print(write_html(ns.dirs[0]))
        return 0
    try:
        print(write_compare(ns.dirs, ns.out or str(Path(ns.dirs[0]) / "compare")))
    except ValueError as exc:
        raise CliError(str(exc)) from None
    return 0
