"""``eb report --plot``: the runs drawn to a PNG or SVG (matplotlib is imported only here, Agg backend)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["plot_runs"]


def plot_runs(runs: list[dict[str, Any]], path: str | Path) -> Path:
    """Draw the runs to ``path`` (.png or .svg): success per subset as grouped bars with the 95 % intervals as
    error bars, and, when the runs are labelled, the share of episodes with each error category.
    matplotlib is imported here only (Agg backend, no display)."""
    from eb_core.exceptions import CliError

    path = Path(path)
    if path.suffix.lower() not in (".png", ".svg"):
        raise CliError(f"--plot {path}: the file must end in .png or .svg (e.g. --plot report.png)")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise CliError("--plot needs matplotlib: pip install 'embodiedbench[report]' "
                       "(or pip install -r requirements.txt)") from None
    from eb_core.errors import CATEGORIES

    subsets = [*dict.fromkeys(s for r in runs for s in r["subsets"]), "all"]
    labelled = [r for r in runs if r["overall"].get("error_analysis")]
    used = [k for k in CATEGORIES if any(r["overall"]["error_analysis"]["categories"][k]["count"] for r in labelled)]
    ncols = 2 if used else 1
    fig, axes = plt.subplots(1, ncols, figsize=(6.5 * ncols + 0.5, 5.0), squeeze=False,
                             gridspec_kw={"width_ratios": [1.3, 1][:ncols]})
    cmap: Any = plt.get_cmap("tab10")  # a ListedColormap: its .colors are the ten tab10 colours
    colours = cmap.colors
    names = [f"{r['model']} / {r['ablation']}" + ("" if len({x['env'] for x in runs}) == 1 else f" ({r['env']})")
             for r in runs]
    _success_bars(axes[0][0], runs, names, subsets, colours)
    handles, legend_labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, legend_labels, fontsize=9, loc="lower center", ncol=min(4, len(runs)), frameon=False)
    if used:
        _error_bars(axes[0][1], runs, labelled, names, used, colours)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path


def _success_bars(ax: Any, runs: list[dict[str, Any]], names: list[str], subsets: list[str], colours: Any) -> None:
    """Success per subset as grouped bars, the 95 % intervals as error bars."""
    width = 0.8 / max(1, len(runs))
    for i, (r, name) in enumerate(zip(runs, names)):
        xs, ys, lo, hi = [], [], [], []
        for j, s in enumerate(subsets):
            block = r["overall"] if s == "all" else r["subsets"].get(s)
            if not block or not block.get("episodes"):
                continue
            value = 100 * float(block["success_rate"])
            ci = block.get("success_rate_ci") or {}
            xs.append(j - 0.4 + width * (i + 0.5))
            ys.append(value)
            lo.append(value - 100 * ci["ci_low"] if ci.get("ci_low") is not None else 0.0)
            hi.append(100 * ci["ci_high"] - value if ci.get("ci_high") is not None else 0.0)
        ax.bar(xs, ys, width=width * 0.92, color=colours[i % len(colours)], label=name,
               yerr=[lo, hi], capsize=3, error_kw={"elinewidth": 1, "ecolor": "#333333"})
        for x, y in zip(xs, ys):
            ax.text(x, y + 1, f"{y:.0f}", ha="center", va="bottom", fontsize=7, color="#222222")
    ax.set_xticks(range(len(subsets)))
    ax.set_xticklabels(subsets, rotation=25 if len(subsets) > 4 else 0, ha="right" if len(subsets) > 4 else "center",
                       fontsize=9)
    ax.set_ylim(0, 110)
    ax.set_ylabel("success rate (%)")
    envs = ", ".join(dict.fromkeys(r["env"] for r in runs))
    ax.set_title(f"Success per subset — {envs} (bars: 95% CI over tasks)", fontsize=10)
    ax.grid(axis="y", alpha=0.3)


def _error_bars(ax2: Any, runs: list[dict[str, Any]], labelled: list[dict[str, Any]], names: list[str],
                used: list[str], colours: Any) -> None:
    """The share of episodes with each error category, one bar per labelled run."""
    from eb_core.errors import CATEGORIES

    h = 0.8 / max(1, len(labelled))
    for i, r in enumerate(labelled):
        cats = r["overall"]["error_analysis"]["categories"]
        ys = [k - 0.4 + h * (i + 0.5) for k in range(len(used))]
        ax2.barh(ys, [100 * cats[c]["episode_rate"] for c in used], height=h * 0.92,
                 color=colours[runs.index(r) % len(colours)], label=names[runs.index(r)])
    ax2.set_yticks(range(len(used)))
    ax2.set_yticklabels([f"{CATEGORIES[c].title}\n({CATEGORIES[c].group})" for c in used], fontsize=8)
    ax2.invert_yaxis()
    ax2.set_xlim(0, 100)
    ax2.set_xlabel("episodes with the error (%)")
    ax2.set_title("Automatic error analysis (all subsets)", fontsize=10)
    ax2.grid(axis="x", alpha=0.3)
