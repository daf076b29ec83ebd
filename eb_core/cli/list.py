"""``eb list``: the installed envs (subsets, task counts, task sets), models, planners, augmenters, metrics and
ablations, each with the plugin that provides it."""

from __future__ import annotations

from typing import Any

from eb_core.exceptions import CliError


def _env_table(registry: Any) -> Any:
    from rich.table import Table

    t = Table(title="Environments", show_lines=False)
    for col in ("name", "plugin", "subsets (tasks)", "task sets (taskset=)", "description"):
        t.add_column(col)
    for name, spec in registry.envs.items():
        subsets = ", ".join(f"{k} ({v})" for k, v in spec.subsets.items())
        total = sum(spec.subsets.values())
        tasksets = ", ".join(["classic", *[s for s in spec.tasksets if s != "classic"]])
        t.add_row(name, spec.plugin, f"{subsets}\n= {total} tasks" if subsets else "", tasksets, spec.description)
    return t


def cmd_list(args: list[str]) -> int:
    from rich.console import Console
    from rich.table import Table

    from eb_core.compose import list_options
    from eb_core.plugins import PluginError, Registry

    if args:
        raise CliError(f"eb list takes no arguments (got {' '.join(args)!r})")
    try:
        registry = Registry.create()
    except PluginError as exc:
        raise CliError(str(exc)) from None
    console = Console(width=max(100, Console().width))
    console.print(_env_table(registry))
    presets = list_options("model")
    ablations = list_options("ablation")
    m = Table(title="Models (model=NAME)")
    for col in ("preset", "backend", "model id / description", "plugin"):
        m.add_column(col)
    for p, node in presets.items():
        b = str(node.get("backend", "(invalid preset)"))
        spec = registry.model_backends.get(b)
        m.add_row(p, b, str(node.get("model_id") or node.get("description") or ""),
                  spec.plugin if spec else "[red]backend not installed[/red]")
    console.print(m)
    for title, specs in (("Planners", registry.planners), ("Augmenters", registry.augmenters),
                         ("Metrics", registry.metrics)):
        tt = Table(title=title)
        for col in ("name", "plugin", "description"):
            tt.add_column(col)
        for name, component in specs.items():
            tt.add_row(name, component.plugin, component.description)
        console.print(tt)
    a = Table(title="Ablations (ablation=NAME)")
    a.add_column("name")
    a.add_column("what changes")
    for name, node in ablations.items():
        a.add_row(name, str((node.get("ablation") or {}).get("description", "")))
    console.print(a)
    return 0
