"""``eb report RUN_DIR [...]``: paper-style tables; ``eb report A B --paired``: is B's difference to A real?"""

from __future__ import annotations

import argparse
import sys
from typing import NoReturn

from eb_core.exceptions import CliError

FORMATS = ("rich", "markdown", "csv", "latex", "html")
_OPTIONS = "--format rich|markdown|csv|latex|html, --out FILE, --plot FILE.png|.svg, --errors, --paired"


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:  # one line, raised instead of exit(2)
        raise CliError(f"report: {message}; options: {_OPTIONS}")


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog="eb report", add_help=False, allow_abbrev=False)
    p.add_argument("dirs", nargs="*")
    p.add_argument("--format", default="rich")
    p.add_argument("--out")
    p.add_argument("--plot")
    p.add_argument("--errors", action="store_true")
    p.add_argument("--paired", action="store_true")
    return p


def cmd_report(args: list[str]) -> int:
    from eb_core.paired import render_paired
    from eb_core.report import render_report

    ns = _parser().parse_args(args)
    if ns.format not in FORMATS:
        raise CliError(f"unknown --format {ns.format!r}; use rich, markdown, csv, latex or html")
    if ns.plot is not None and not ns.plot.lower().endswith((".png", ".svg")):
        raise CliError(f"--plot {ns.plot!r}: the file must end in .png or .svg, e.g. --plot report.png")
    if not ns.dirs:
        raise CliError("report needs at least one run directory, e.g. eb report runs/navigation/oracle/none/default")
    if ns.paired:
        if ns.format in ("latex", "html"):
            raise CliError(f"--paired prints rich, markdown or csv (got --format {ns.format})")
        render_paired(ns.dirs, ns.format, ns.out)
    else:
        render_report(ns.dirs, ns.format, ns.out, plot=ns.plot, errors=ns.errors)
        if ns.plot:
            print(f"plot -> {ns.plot}", file=sys.stderr)
    return 0
