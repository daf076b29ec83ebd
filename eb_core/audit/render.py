"""The audit as plain text: one summary table, then each probe's detail rows and warnings."""

from __future__ import annotations

import textwrap

from eb_core.audit.contract import AuditProbe, ProbeResult

__all__ = ["format_audit"]


def _status(res: ProbeResult) -> str:
    if not res.passed:
        return "FAIL"
    if res.warning:
        return "warn"
    return "skip" if res.skipped else "pass"


def _text_table(headers: list[str], rows: list[list[str]], widths: dict[int, int] | None = None) -> list[str]:
    """A plain-text table; a cell longer than its column's limit in ``widths`` wraps onto more lines."""
    widths = widths or {}
    wrapped = [[textwrap.wrap(str(c), widths[i], break_on_hyphens=False) or [""] if i in widths else [str(c)]
                for i, c in enumerate(r)] for r in rows]
    w = [max([len(h)] + [len(ln) for r in wrapped for ln in r[i]]) for i, h in enumerate(headers)]
    out = ["  ".join(h.ljust(w[i]) for i, h in enumerate(headers)).rstrip(), "  ".join("-" * x for x in w)]
    for r in wrapped:
        for k in range(max(len(c) for c in r)):
            out.append("  ".join((c[k] if k < len(c) else "").ljust(w[i]) for i, c in enumerate(r)).rstrip())
    return out


def format_audit(env_name: str, results: list[tuple[AuditProbe, ProbeResult]], n_tasks: int,
                 note: str = "") -> str:
    """The audit as plain text: one summary table, then each probe's detail rows and warnings."""
    rows = []
    for probe, res in results:
        shown = ", ".join(res.failing_tasks[:5])
        more = len(res.failing_tasks) - 5
        if more > 0:
            shown += f" (+{more} more)"
        rows.append([res.name, probe.description, res.value, res.threshold, _status(res), shown])
    lines = [f"eb audit: {env_name}, {n_tasks} tasks" + (f" (random-action probes: {note})" if note else ""), ""]
    lines += _text_table(["probe", "guards against", "measured", "threshold", "status", "failing tasks"], rows,
                         widths={1: 36, 2: 56, 3: 34, 5: 44})
    for probe, res in results:
        if res.rows:
            keys = list(dict.fromkeys(k for r in res.rows for k in r))
            lines += ["", f"{res.name}:"]
            cells = [[str(r.get(k, "")) for k in keys] for r in res.rows]
            lines += _text_table(keys, cells, widths={len(keys) - 1: 100})
        if res.warning:
            lines += ["", f"warning ({res.name}): {res.warning}"]
        if not res.passed and len(res.failing_tasks) > 5:
            lines += ["", f"{res.name} failing tasks: {', '.join(res.failing_tasks)}"]
    lines += ["", _verdict(results)]
    return "\n".join(lines)


def _verdict(results: list[tuple[AuditProbe, ProbeResult]]) -> str:
    """``audit passed (7/7 probes pass, 2 skipped)``: skipped probes are counted apart, not as passes."""
    failed = [r.name for _, r in results if not r.passed]
    skipped = sum(r.skipped and r.passed for _, r in results)
    ran = len(results) - skipped
    note = f", {skipped} skipped" if skipped else ""
    return (f"audit {'FAILED: ' + ', '.join(failed) if failed else 'passed'} "
            f"({ran - len(failed)}/{ran} probes pass{note})")

