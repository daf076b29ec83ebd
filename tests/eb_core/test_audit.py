"""``eb audit``'s generic probes, each fed a sound task set (passes) and a deliberately broken one (fails)."""

from __future__ import annotations

import json
import random
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from eb_core import DiscreteActionSpace, Env, Observation, PromptParts, StepResult, Task
from eb_core.audit import (
    FRESH_PER_SUBSET,
    AuditProbe,
    AuditSetup,
    BlindPolicy,
    ProbeResult,
    format_audit,
    grammar_issues,
    p50,
    permutation_p_value,
    probe_blind_policies,
    probe_closed_loop,
    probe_grammar,
    probe_noise_curve,
    probe_parallel_forms,
    probe_templates,
    probe_unique_instructions,
    run_audit,
    sample_positions,
)

DIGITS = tuple(f"press {d}" for d in range(10))
TEMPLATES = ["Enter the code {c}.", "Type {c} on the keypad.", "The lock opens with {c}; key it in.",
             "Punch in {c}, please.", "Unlock the door: the code is {c}.", "Key in the digits {c}.",
             "Open the safe with {c}.", "Use the keypad to enter {c}.", "Press {c} in that order.",
             "The combination is {c}. Enter it.", "Dial {c} on the lock.", "Tap the buttons {c}, in order."]


def lock_tasks(seed: int = 0, per_subset: int = 30, lengths: dict[str, int] | None = None) -> list[dict[str, Any]]:
    """Keypad tasks: press a code of distinct digits in order (a wrong digit starts the entry over)."""
    lengths = lengths or {"short": 3, "long": 4}
    rng = random.Random(seed)
    out = []
    for subset, n in lengths.items():
        codes: set[tuple[int, ...]] = set()
        while len(codes) < per_subset:
            codes.add(tuple(rng.sample(range(10), n)))
        for i, code in enumerate(sorted(codes, key=lambda c: rng.random())):
            k = i % len(TEMPLATES)
            text = TEMPLATES[k].format(c="-".join(map(str, code)))
            out.append({"id": f"{subset}-{i:02d}", "subset": subset, "instruction": text,
                        "metadata": {"code": list(code), "template": k}})
    return out


def write_tasks(path: Path, tasks: list[dict[str, Any]]) -> str:
    path.write_text(json.dumps(tasks))
    return str(path)


class LockEnv(Env):
    """A keypad. ``task_file`` holds the tasks (a JSON list); ``loop_expert`` makes the expert press a wrong
    digit forever for those task ids; ``wrong_expert`` makes it wrong everywhere."""

    name = "lock"

    def __init__(self, resolution: int = 64, multi_view: bool = False, task_file: str = "",
                 loop_expert: tuple[str, ...] = (), wrong_expert: bool = False, render: bool = True) -> None:
        self.loop_expert, self.wrong_expert, self.render = set(loop_expert), wrong_expert, render
        self.code: list[int] = []
        self.k = 0
        self.task: Task | None = None

    @classmethod
    def load_tasks(cls, task_file: str = "", **_: Any) -> list[Task]:
        return [Task(**t) for t in json.loads(Path(task_file).read_text())]

    def _obs(self) -> Observation:
        assert not self.render, "the audit must switch rendering off"
        return Observation(text=f"{self.k} digits entered")

    def reset(self, task: Task, seed: int) -> Observation:
        self.task, self.code, self.k = task, list(task.metadata["code"]), 0
        return self._obs()

    def step(self, action: Any) -> StepResult:
        d = int(action)
        if d == self.code[self.k]:
            self.k += 1
        else:
            self.k = 1 if d == self.code[0] else 0
        done = self.k == len(self.code)
        return StepResult(observation=self._obs(), action_success=True, feedback="beep", done=done,
                          task_success=done, progress=self.k / len(self.code))

    def action_space(self) -> DiscreteActionSpace:
        return DiscreteActionSpace(actions=DIGITS)

    def prompt_parts(self) -> PromptParts:
        return PromptParts(role="You open a keypad lock.")

    def expert_plan(self) -> list[int] | None:
        assert self.task is not None
        if self.wrong_expert or self.task.id in self.loop_expert:
            return [(self.code[self.k] + 1) % 10]
        return self.code[self.k:]


def setup_for(tmp_path: Path, tasks: list[dict[str, Any]], **kw: Any) -> AuditSetup:
    params = {"task_file": write_tasks(tmp_path / "tasks.json", tasks), **kw.pop("params", {})}
    return AuditSetup(env_name="lock", env_cls=LockEnv, tasks=LockEnv.load_tasks(**params), max_steps=20,
                      env_params=params, **kw)


# -- instructions ----------------------------------------------------------------------------------------


def test_grammar_finds_article_doubling_and_spacing_defects():
    assert grammar_issues("Put a apple in the fridge.") == ["'a apple' (use 'an')"]
    assert grammar_issues("Grab an cup.") == ["'an cup' (use 'a')"]
    assert grammar_issues("Walk to the the sofa.") == ["doubled word 'the the'"]
    assert "double space" in grammar_issues("Walk to  the sofa.")
    assert "space before punctuation" in grammar_issues("Walk to the sofa .")
    assert "unbalanced '()'" in grammar_issues("Walk to the sofa (the red one.")
    assert "sentence starts lowercase" in grammar_issues("Walk to the sofa. then stop.")
    for fine in ("Wait an hour, then take a unicorn toy, an umbrella and a one-way ticket.",
                 "Take an 8-ball, a European plate, an FBI file and a useful tool.",
                 "An unopened can sits by a urinal; an orange is on a uniform shelf.", "Put the cup in the sink."):
        assert grammar_issues(fine) == [], fine


def test_instruction_probes_pass_a_sound_set(tmp_path):
    setup = setup_for(tmp_path, lock_tasks())
    for probe in (probe_unique_instructions, probe_templates, probe_grammar):
        res = probe(setup)
        assert res.passed and not res.failing_tasks and not res.skipped, res


def test_duplicates_and_few_templates_and_bad_grammar_fail(tmp_path):
    tasks = lock_tasks()
    for t in tasks[1:5]:  # four copies of the first task's wording (86.7 % unique), and only three templates
        t["instruction"] = tasks[0]["instruction"]
    for t in tasks:
        if t["subset"] == "long":
            t["metadata"]["template"] %= 3
    tasks[7]["instruction"] = "Enter a 8 then the the rest."
    setup = setup_for(tmp_path, tasks)
    unique = probe_unique_instructions(setup)
    assert not unique.passed and unique.failing_tasks == [t["id"] for t in tasks[1:5]]
    assert f"{tasks[1]['id']} = {tasks[0]['id']}" in unique.value and "86.7 %" in unique.value
    templates = probe_templates(setup)
    assert not templates.passed and "long (3)" in templates.value
    assert set(templates.failing_tasks) == {t["id"] for t in tasks if t["subset"] == "long"}
    grammar = probe_grammar(setup)
    assert not grammar.passed and grammar.failing_tasks == [tasks[7]["id"]]
    assert "'a 8' (use 'an')" in grammar.rows[0]["issues"] and "doubled word" in grammar.rows[0]["issues"]


def test_templates_probe_is_skipped_without_template_metadata(tmp_path):
    tasks = lock_tasks()
    for t in tasks:
        del t["metadata"]["template"]
    res = probe_templates(setup_for(tmp_path, tasks))
    assert res.passed and res.skipped


# -- blind policies --------------------------------------------------------------------------------------


def test_blind_policies_pass_a_sound_set(tmp_path):
    res = probe_blind_policies(setup_for(tmp_path, lock_tasks()))
    assert res.passed, res
    assert res.rows and float(res.rows[0]["success"].split()[0]) <= 5.0
    assert res.value.startswith("34 policies (10 constant, 24 cycle)")  # no turn actions on a keypad


def test_a_constant_action_that_solves_a_subset_fails(tmp_path):
    tasks = lock_tasks()
    for t in tasks[:6]:  # six short tasks open with a single 7: "always press 7" solves 20 % of the subset
        t["metadata"]["code"] = [7]
    res = probe_blind_policies(setup_for(tmp_path, tasks))
    assert not res.passed
    assert {t["id"] for t in tasks[:6]} <= set(res.failing_tasks)
    assert all(t.startswith("short-") for t in res.failing_tasks)  # the sound long subset is not blamed
    assert "'press 7'" in res.rows[0]["policy"] and float(res.rows[0]["success"].split()[0]) >= 20.0
    assert "always 'press 7'" in {r["policy"] for r in res.rows}


def test_a_world_can_add_named_blind_policies(tmp_path):
    tasks = lock_tasks()
    for t in tasks[30:36]:
        t["metadata"]["code"] = [9, 8, 1, 2]  # no sampled cycle hits this, the named one does
    named = BlindPolicy("the installer's default code", ("press 9", "press 8", "press 1", "press 2"))
    res = probe_blind_policies(setup_for(tmp_path, tasks, blind_policies=[named]))
    assert not res.passed and res.rows[0]["policy"] == named.name and "1 named by the world" in res.value
    assert set(res.failing_tasks) == {t["id"] for t in tasks[30:36]}


# -- the expert ------------------------------------------------------------------------------------------


def test_closed_loop_oracle_and_noise_curve_pass_a_sound_set(tmp_path):
    setup = setup_for(tmp_path, lock_tasks())
    closed = probe_closed_loop(setup)
    assert closed.passed and closed.value.startswith("100.0 % (60/60)")
    curve = probe_noise_curve(setup)
    assert curve.passed, curve
    rows = {r["subset"]: r for r in curve.rows}
    assert rows["long"]["p=0"] == "100" and int(rows["long"]["p=1"]) < int(rows["long"]["p=0.3"])
    assert float(rows["long"]["p50"]) < float(rows["short"]["p50"])  # the longer code breaks sooner


def test_an_expert_that_loops_fails_the_closed_loop_probe(tmp_path):
    loops = ("short-03", "long-11")
    res = probe_closed_loop(setup_for(tmp_path, lock_tasks(), params={"loop_expert": loops}))
    assert not res.passed and res.failing_tasks == list(loops)
    assert all(r["end"] == "max_steps" for r in res.rows)


def test_success_that_rises_with_noise_fails(tmp_path):
    tasks = lock_tasks(lengths={"one": 1, "two": 2}, per_subset=10)
    res = probe_noise_curve(setup_for(tmp_path, tasks, params={"wrong_expert": True}))
    assert not res.passed and "rises with noise" in res.value
    rows = {r["subset"]: r for r in res.rows}
    assert rows["one"]["p=0"] == "0" and int(rows["one"]["p=1"]) > 50
    assert set(res.failing_tasks) <= {t["id"] for t in tasks} and res.failing_tasks


def test_p50_interpolates_and_warns_on_flat_curves(tmp_path):
    assert p50([(0.0, 1.0), (0.5, 0.8), (0.7, 0.4), (1.0, 0.0)]) == pytest.approx(0.5 + 0.2 * 0.3 / 0.4)
    assert p50([(0.0, 0.4), (1.0, 0.0)]) == 0.0
    assert p50([(0.0, 1.0), (1.0, 0.6)]) is None
    # a one-digit code survives almost any noise within 20 steps: the subset tells models apart poorly
    tasks = lock_tasks(lengths={"one": 1, "four": 4}, per_subset=10)
    res = probe_noise_curve(setup_for(tmp_path, tasks))
    assert res.passed and res.warning and "one (p50" in res.warning and "four" not in res.warning


# -- parallel forms --------------------------------------------------------------------------------------


def test_permutation_test_tells_sampling_from_a_real_difference():
    rng = np.random.default_rng(0)
    same = permutation_p_value(rng.random(40), rng.random(40), permutations=4000)
    differ = permutation_p_value(rng.random(40) * 0.5, rng.random(40) * 0.5 + 0.4, permutations=4000)
    assert same > 0.05 and differ < 0.001


def make_generator(lengths_for_new_seeds: dict[str, int]):
    calls = []

    def generate(out: str, seed: int = 0) -> str:
        calls.append(seed)
        write_tasks(Path(out), lock_tasks(seed=seed, lengths=lengths_for_new_seeds))
        return "ok"

    generate.calls = calls  # type: ignore[attr-defined]
    return generate


def test_parallel_forms_pass_when_the_generator_is_stable(tmp_path):
    gen = make_generator({"short": 3, "long": 4})
    res = probe_parallel_forms(setup_for(tmp_path, lock_tasks(), generator=gen, parallel_seed=5))
    assert gen.calls == [5]
    assert res.passed and not res.skipped, res
    assert {r["subset"] for r in res.rows} == {"short", "long"} and all(float(r["p-value"]) >= 0.01 for r in res.rows)


def test_parallel_forms_fail_when_a_fresh_form_is_harder(tmp_path):
    gen = make_generator({"short": 4, "long": 4})  # a fresh seed gives long codes in the short subset
    res = probe_parallel_forms(setup_for(tmp_path, lock_tasks(), generator=gen))
    assert not res.passed and "short (" in res.value and "long (" not in res.value
    assert res.failing_tasks and all(t.startswith("short-") for t in res.failing_tasks)
    quick = probe_parallel_forms(setup_for(tmp_path, lock_tasks(), generator=gen, quick=True))
    assert quick.passed and quick.skipped


def test_parallel_forms_compare_with_a_given_file(tmp_path):
    other = write_tasks(tmp_path / "other.json", lock_tasks(seed=3, lengths={"short": 3, "long": 2}))
    res = probe_parallel_forms(setup_for(tmp_path, lock_tasks(), parallel_source=other))
    assert not res.passed and "long (" in res.value and f"given {other}" in res.value


class LockFolderEnv(LockEnv):
    """Like navigation: ``task_file`` is a file or a folder of per-subset files, and there is no ``task_dir``."""

    @classmethod
    def load_tasks(cls, task_file: str = "") -> list[Task]:  # type: ignore[override]
        path = Path(task_file)
        files = sorted(path.glob("*.json")) if path.is_dir() else [path]
        return [Task(**t) for f in files for t in json.loads(f.read_text())]


def test_parallel_forms_read_a_folder_through_task_file_where_the_world_has_no_task_dir(tmp_path):
    """A fresh hard form is a folder (one file per subset); the probe crashed on navigation ("unknown navigation env
    param 'task_dir'") because it always passed a folder as task_dir."""
    other = tmp_path / "other"
    other.mkdir()
    fresh = lock_tasks(seed=3, lengths={"short": 3, "long": 2})
    for subset in ("short", "long"):
        write_tasks(other / f"{subset}.json", [t for t in fresh if t["subset"] == subset])
    params = {"task_file": write_tasks(tmp_path / "tasks.json", lock_tasks())}
    setup = AuditSetup(env_name="lock", env_cls=LockFolderEnv, tasks=LockFolderEnv.load_tasks(**params),
                       max_steps=20, env_params=params, parallel_source=str(other))
    res = probe_parallel_forms(setup)
    assert "crashed" not in res.value and "long (" in res.value and not res.passed, res


# -- the whole audit -------------------------------------------------------------------------------------


class LockWithProbe(LockEnv):
    @classmethod
    def audit_probes(cls) -> list[AuditProbe]:
        def run(tasks: list[Task], params: dict[str, Any]) -> ProbeResult:
            bad = [t.id for t in tasks if len(set(t.metadata["code"])) < len(t.metadata["code"])]
            return ProbeResult(name="code_digits", passed=not bad, value=f"{len(bad)} codes repeat a digit",
                               threshold="distinct digits", failing_tasks=bad)

        return [AuditProbe("code_digits", "A repeated digit makes a code easier to guess.", run)]


def test_run_audit_runs_generic_then_world_probes_and_prints_one_table(tmp_path):
    tasks = lock_tasks()
    tasks[0]["metadata"]["code"] = [4, 4]
    params = {"task_file": write_tasks(tmp_path / "t.json", tasks)}
    setup = AuditSetup(env_name="lock", env_cls=LockWithProbe, tasks=LockWithProbe.load_tasks(**params),
                       max_steps=20, env_params=params, quick=True, quick_per_subset=30)
    results = run_audit(setup)
    names = [r.name for _, r in results]
    assert names == ["instruction_unique", "instruction_templates", "instruction_grammar", "blind_policies",
                     "feedback_policies", "closed_loop_oracle", "noise_curve", "parallel_forms", "code_digits"]
    failed = {r.name for _, r in results if not r.passed}
    assert failed == {"code_digits"}
    text = format_audit("lock", results, len(tasks))
    assert "code_digits" in text and "FAIL" in text and tasks[0]["id"] in text and "p50" in text
    # skipped probes (parallel forms under --quick; no feedback policies for a keypad) are not counted as passes
    assert "audit FAILED: code_digits (6/7 probes pass, 2 skipped)" in text
    with pytest.raises(KeyError, match="unknown probe 'nope'.*code_digits"):
        run_audit(setup, only=["nope"])
    only = run_audit(setup, only=["closed_loop_oracle"])
    assert [r.name for _, r in only] == ["closed_loop_oracle"] and only[0][1].passed


def test_slow_worlds_play_a_seeded_random_sample_of_tasks_per_subset(tmp_path, monkeypatch):
    setup = setup_for(tmp_path, lock_tasks(), per_subset=5)
    picked = setup.sampled_tasks()
    short = [t.id for t in picked if t.subset == "short"]
    positions = sample_positions(30, 5, seed=0)
    assert short == [f"short-{i:02d}" for i in positions] and len(set(short)) == 5
    assert short != ["short-00", "short-06", "short-12", "short-18", "short-24"]  # not the even spread it was
    # every subset of one size at the same positions (worlds whose subsets share their starts rely on it)
    assert [t.id.split("-")[1] for t in picked if t.subset != "short"] == [i.split("-")[1] for i in short]
    assert len(picked) == 10 and len(setup.episode_tasks()) == 60  # the closed loop still plays every task
    assert sample_positions(30, 5, seed=1) != positions and sample_positions(30, 40) == list(range(30))
    curve = probe_noise_curve(setup)
    assert "p50" in curve.value and setup._cache[("curve", 0.5, 0)].keys() == {t.id for t in picked}
    # no cap given: it follows from the cost of a random step (measured once; faked here) and the budget
    fast = setup_for(tmp_path, lock_tasks())
    monkeypatch.setattr(AuditSetup, "random_step_seconds", lambda self: 0.0001)
    assert fast.cap() is None and fast.sampling_note() == "every task"
    slow = setup_for(tmp_path, lock_tasks())
    monkeypatch.setattr(AuditSetup, "random_step_seconds", lambda self: 0.05)
    assert slow.cap() == 5 and len(slow.sampled_tasks()) == 10
    assert "5 tasks per subset" in slow.sampling_note() and "50 ms" in slow.sampling_note()


def test_parallel_forms_compare_random_samples_that_do_not_alias_with_a_cycling_order(tmp_path):
    # ALFRED's generator writes task types in turn (period 5): every 2.5th task of 50 is always one of two types,
    # so an evenly spaced sample of the shipped file compared two easy types with a fresh form of all five
    # (visual_appearance 87 % against 70 %, p = 0.002, three fresh forms in a row)
    setup = setup_for(tmp_path, lock_tasks(per_subset=50), per_subset=20)
    family = {t.id: int(t.id.split("-")[1]) % 5 for t in setup.tasks}
    # the policy probes' sample does not alias with it either (an evenly spaced one held only families 0 and 2)
    policy = [t for t in setup.sampled_tasks() if t.subset == "short"]
    assert len(policy) == 20 and {family[t.id] for t in policy} == {0, 1, 2, 3, 4}
    drawn = [t for t in setup.forms_sample(list(setup.tasks)) if t.subset == "short"]
    assert len(drawn) == 20 and {family[t.id] for t in drawn} == {0, 1, 2, 3, 4}
    assert [t.id for t in drawn] == sorted(t.id for t in drawn)  # in the file's order
    again = setup_for(tmp_path, lock_tasks(per_subset=50), per_subset=20).forms_sample(list(setup.tasks))
    assert [t.id for t in again if t.subset == "short"] == [t.id for t in drawn]  # seeded: the same every run
    other = setup_for(tmp_path, lock_tasks(per_subset=50), per_subset=20, seed=1).forms_sample(list(setup.tasks))
    assert [t.id for t in other if t.subset == "short"] != [t.id for t in drawn]


def test_two_workers_give_the_same_results_as_one(tmp_path):
    tasks = lock_tasks(per_subset=10)
    one = setup_for(tmp_path, tasks, params={"loop_expert": ("short-02",)})
    two = setup_for(tmp_path, tasks, params={"loop_expert": ("short-02",)}, workers=2)
    for probe in (probe_blind_policies, probe_closed_loop, probe_noise_curve):
        assert probe(one) == probe(two)
    assert probe_closed_loop(two).failing_tasks == ["short-02"]


def test_pool_workers_end_quietly_under_the_eb_command_sigterm_handler(tmp_path, capfd):
    """eb installs a SIGTERM handler that raises (for the command itself); the audit's forked pool workers, ended by
    the pool with SIGTERM, must not inherit it and print a traceback each."""
    import signal

    from eb_core.cli import _on_sigterm

    two = setup_for(tmp_path, lock_tasks(per_subset=10), workers=2)
    old = signal.signal(signal.SIGTERM, _on_sigterm)
    try:
        for _ in range(3):
            probe_blind_policies(two)
    finally:
        signal.signal(signal.SIGTERM, old)
    err = capfd.readouterr().err
    assert "Terminated" not in err and "Traceback" not in err


# -- cheaper full audits: a sample fresh form, work beside the episode probes ----------------------------


def test_a_sample_form_is_generated_with_only_the_tasks_it_plays(tmp_path):
    calls: list[tuple[int, int]] = []

    def form(out: str, seed: int, per_subset: int) -> None:
        calls.append((seed, per_subset))
        write_tasks(Path(out), lock_tasks(seed=seed, per_subset=per_subset))

    res = probe_parallel_forms(setup_for(tmp_path, lock_tasks(), form_generator=form, parallel_seed=7,
                                         parallel_per_subset=12))
    assert calls == [(7, 12)]
    assert res.passed, res
    assert "12 tasks per subset" in res.value and {r["tasks"] for r in res.rows} == {"30 / 12"}
    # the default size is FRESH_PER_SUBSET, never more than the shipped form plays per subset
    assert setup_for(tmp_path, lock_tasks()).fresh_per_subset() == min(FRESH_PER_SUBSET, 30)
    assert setup_for(tmp_path, lock_tasks(), per_subset=5).fresh_per_subset() == 5

    def harder(out: str, seed: int, per_subset: int) -> None:  # long codes in the short subset too
        write_tasks(Path(out), lock_tasks(seed=seed, per_subset=per_subset, lengths={"short": 5, "long": 4}))

    bad = probe_parallel_forms(setup_for(tmp_path, lock_tasks(), form_generator=harder))
    assert not bad.passed and "short (" in bad.value and "counts differ" not in bad.value


def test_the_form_generator_is_found_beside_the_task_generator():
    from eb_core.audit import find_form_generator

    nav_generate = pytest.importorskip("eb_navigation.generate")

    assert find_form_generator(nav_generate.generate) is nav_generate.audit_form
    assert find_form_generator(make_generator({"short": 3})) is None and find_form_generator(None) is None


def test_the_shipped_form_shares_its_noisy_episodes_with_the_noise_curve(tmp_path):
    setup = setup_for(tmp_path, lock_tasks(per_subset=10), generator=make_generator({"short": 3, "long": 4}))
    probe_noise_curve(setup)
    curve_half = dict(setup._cache[("curve", 0.5, 0)])
    probe_parallel_forms(setup)
    assert setup._cache[("curve", 0.5, 0)] == curve_half  # reused, not replayed
    assert len(setup._cache[("curve", 0.5, 9)]) == 20  # the other repeats were added
    assert any(k[1] != 0.5 and len(k) == 4 for k in setup._cache if k[0] == "curve")  # the fresh form's own


def test_background_work_gives_the_same_audit_as_one_process(tmp_path):
    tasks = lock_tasks(per_subset=12)
    tasks[0]["metadata"]["code"] = [4, 4]
    params = {"task_file": write_tasks(tmp_path / "t.json", tasks)}

    def form(out: str, seed: int, per_subset: int) -> None:
        write_tasks(Path(out), lock_tasks(seed=seed, per_subset=per_subset))

    def audit(workers: int) -> list[tuple[str, ProbeResult]]:
        setup = AuditSetup(env_name="lock", env_cls=LockWithProbe, tasks=LockWithProbe.load_tasks(**params),
                           max_steps=20, env_params=params, form_generator=form, workers=workers)
        return [(p.name, r) for p, r in run_audit(setup)]

    one, two = audit(1), audit(2)
    assert one == two
    assert [n for n, _ in two][-2:] == ["parallel_forms", "code_digits"]
    assert dict(two)["code_digits"].failing_tasks == [tasks[0]["id"]]
    assert "tasks per subset" in dict(two)["parallel_forms"].value


class LockWithCrashingProbe(LockEnv):
    @classmethod
    def audit_probes(cls) -> list[AuditProbe]:
        def run(tasks: list[Task], params: dict[str, Any]) -> ProbeResult:
            raise ValueError("no digits today")

        return [AuditProbe("crashes", "A probe that fails with an error.", run)]


def test_a_world_probe_crashing_in_the_background_fails_the_audit(tmp_path):
    setup = setup_for(tmp_path, lock_tasks(per_subset=5), workers=2)
    setup.env_cls = LockWithCrashingProbe
    [(_, res)] = run_audit(setup, only=["crashes"])
    assert not res.passed and "ValueError: no digits today" in res.value


def test_detectable_difference_grows_as_the_fresh_form_shrinks():
    from eb_core.audit import detectable_difference

    rng = np.random.default_rng(1)
    shipped = list(rng.binomial(10, 0.6, 60) / 10)
    full, sample = detectable_difference(shipped, shipped), detectable_difference(shipped, shipped[:20])
    sd = float(np.std(shipped, ddof=1))
    assert full == pytest.approx((2.5758 + 0.8416) * sd * (2 / 60) ** 0.5, rel=1e-3)
    assert sample > full and sample / full == pytest.approx(((1 / 60 + 1 / 20) / (2 / 60)) ** 0.5, rel=0.15)
    # a real gap of that size is found by the permutation test (one draw; the test has ~80 % power there)
    shifted = [min(1.0, x + 1.3 * full) for x in shipped]
    assert permutation_p_value(shipped, shifted, permutations=4000) < 0.01


def test_an_audit_of_one_subset_compares_with_that_subset_of_the_fresh_form(tmp_path):
    short_only = [t for t in lock_tasks() if t["subset"] == "short"]
    res = probe_parallel_forms(setup_for(tmp_path, short_only, generator=make_generator({"short": 3, "long": 4})))
    assert res.passed and [r["subset"] for r in res.rows] == ["short"], res
    missing = probe_parallel_forms(setup_for(tmp_path, lock_tasks(), generator=make_generator({"short": 3})))
    assert not missing.passed and "long (only in the shipped form)" in missing.value
