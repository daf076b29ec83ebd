"""``eb plan``'s arithmetic against a Monte-Carlo simulation, and its command line."""

from __future__ import annotations

import numpy as np
import pytest

from eb_core.budget import Noise, cmd_plan, plan_rows, simulate_width


@pytest.mark.parametrize(("population", "repeats"), [
    (np.array([0.1, 0.9] * 30), 1),      # between 0.16, within 0.09
    (np.array([0.1, 0.9] * 30), 4),
    (np.linspace(0.0, 1.0, 60), 2),      # a spread of task difficulties
    (np.full(60, 0.5), 3),               # no between-task spread at all: repeats do everything
])
def test_planned_width_agrees_with_simulation(population, repeats):
    between = float(np.var(population))
    within = float(np.mean(population * (1 - population)))
    noise = Noise(rate=float(population.mean()), between=between, within=within)
    planned = plan_rows(noise, "width", 0.2, available=len(population), repeats=(repeats,))[0]["with_all_tasks"]
    simulated = simulate_width(population, repeats, n_sims=6000)
    assert simulated == pytest.approx(planned, rel=0.06)


def test_tasks_needed_reach_the_target_and_more_repeats_never_need_more_tasks():
    noise = Noise(rate=0.4, between=0.15, within=0.09)
    rows = plan_rows(noise, "width", 0.10, available=300, repeats=(1, 2, 3, 5))
    needs = [r["tasks_needed"] for r in rows]
    assert needs == sorted(needs, reverse=True) and needs[0] > needs[-1]
    again = plan_rows(noise, "width", 0.10, available=needs[0], repeats=(1,))[0]
    assert again["with_all_tasks"] <= 0.10 + 1e-9
    diff = plan_rows(noise, "diff", 0.05, available=300, discordant=0.3)
    assert not any(r["feasible"] for r in diff)  # docs/statistics.md: 5 points is out of reach on 300 tasks


def test_command_line(capsys, tmp_path):
    from eb_core.plugins import Registry

    n = sum(Registry.create().envs["corridor"].subsets.values())
    assert cmd_plan(["env=corridor", "target=width:10"]) == 0
    out = capsys.readouterr().out
    assert f"corridor (all subsets, {n} tasks)" in out and "tasks needed" in out
    assert "NO" in out  # a fixture world's few tasks cannot give a 10-point interval
    assert cmd_plan(["env=corridor", "target=width"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "target=width:10" in err
    assert cmd_plan(["env=corridor", "subset=nope", "target=diff:10"]) == 2
    assert "available:" in capsys.readouterr().err
    assert cmd_plan(["env=corridor", "target=diff:10", "from=" + str(tmp_path)]) == 2
