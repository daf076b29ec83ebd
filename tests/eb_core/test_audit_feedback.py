"""``eb audit``'s feedback-reacting blind policies, task sets and hard fresh forms, on two tiny worlds: a corridor
walked with navigation's move names, and a shelf of look-alike boxes opened one by one."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from eb_core import DiscreteActionSpace, Env, Observation, PromptParts, StepResult, Task
from eb_core.audit import (
    AuditSetup,
    CandidateSearch,
    ReactivePolicy,
    feedback_policies,
    format_audit,
    probe_feedback_policies,
    probe_parallel_forms,
    run_audit,
)
from eb_core.specs import EnvSpec

MOVES = ("Move forward by 0.25 meters", "Move sideways to the right by 0.25 meters",
         "Move sideways to the left by 0.25 meters", "Turn right by 90 degrees", "Turn left by 90 degrees")


class Yard(Env):
    """A 5 x 5 yard, the agent facing +y from (0, 0); a task's ``wall`` blocks the cells it lists. The goal is a
    cell; a bump (a move into a wall or off the yard) fails the action and leaves the agent where it was."""

    name = "yard"

    def __init__(self, resolution: int = 64, multi_view: bool = False, task_file: str = "",
                 render: bool = True) -> None:
        self.pos, self.heading, self.task = (0, 0), 0, None

    @classmethod
    def load_tasks(cls, task_file: str = "", taskset: str = "classic", **_: Any) -> list[Task]:
        """``task_file``, or for another task set the file beside it named ``<stem>.<taskset>.json``."""
        path = Path(task_file) if taskset == "classic" else Path(task_file).with_suffix(f".{taskset}.json")
        return [Task(**t) for t in json.loads(path.read_text())]

    def reset(self, task: Task, seed: int) -> Observation:
        self.task, self.pos, self.heading = task, (0, 0), 0
        return Observation(text="")

    def step(self, action: Any) -> StepResult:
        assert self.task is not None
        name = MOVES[int(action)]
        dx, dy = [(0, 1), (1, 0), (0, -1), (-1, 0)][self.heading]
        ok = True
        if name.startswith("Turn"):
            self.heading = (self.heading + (1 if "right" in name else -1)) % 4
        else:
            if "right" in name:
                dx, dy = dy, -dx
            elif "left" in name:
                dx, dy = -dy, dx
            nxt = (self.pos[0] + dx, self.pos[1] + dy)
            ok = 0 <= nxt[0] < 5 and 0 <= nxt[1] < 5 and list(nxt) not in self.task.metadata["wall"]
            self.pos = nxt if ok else self.pos
        done = list(self.pos) == self.task.metadata["goal"]
        return StepResult(observation=Observation(text=""), action_success=ok, feedback="ok" if ok else "bump",
                          done=done, task_success=done)

    def action_space(self) -> DiscreteActionSpace:
        return DiscreteActionSpace(actions=MOVES)

    def prompt_parts(self) -> PromptParts:
        return PromptParts(role="You walk a yard.")


def yard_tasks(goals: list[list[int]], wall: list[list[int]], subset: str = "base",
               taskset: str = "classic") -> list[dict[str, Any]]:
    return [{"id": f"{subset}-{taskset}-{i}", "subset": subset, "instruction": f"Walk to cell {g}.",
             "metadata": {"goal": g, "wall": wall, "taskset": taskset}} for i, g in enumerate(goals)]


def yard_setup(tmp_path: Path, tasks: list[dict[str, Any]], **kw: Any) -> AuditSetup:
    params = {"task_file": str(tmp_path / "yard.json")}
    for name in ("classic", "hard"):
        path = Path(params["task_file"]) if name == "classic" else tmp_path / f"yard.{name}.json"
        path.write_text(json.dumps([t for t in tasks if t["metadata"]["taskset"] == name]))
    taskset = kw.get("taskset", "classic")
    return AuditSetup(env_name="yard", env_cls=Yard, tasks=Yard.load_tasks(**params, taskset=taskset), max_steps=12,
                      env_params=params, **kw)


def test_walking_forward_and_side_stepping_on_a_bump_is_caught(tmp_path):
    # a wall right ahead at (0, 2): forward bumps, a side-step right and forward again reach (1, 4)
    bumped = yard_tasks([[1, 4]] * 4 + [[9, 9]] * 4, wall=[[0, 2]])  # (9, 9) lies outside the yard
    res = probe_feedback_policies(yard_setup(tmp_path, bumped))
    assert not res.passed and "turn or side-step after a failure" in res.value
    top = res.rows[0]
    assert "after a failure 'Move sideways to the right by 0.25 meters'" in top["policy"]
    assert top["success"] == "50.0 %" and "base 50.0" in top["per subset (%)"]
    assert set(res.failing_tasks) == {f"base-classic-{i}" for i in range(4)}
    # goals inside an open yard: a walker that follows the edges never gets there
    open_yard = yard_tasks([[2, 2], [2, 3], [3, 2], [1, 2]] + [[9, 9]] * 4, wall=[])
    assert probe_feedback_policies(yard_setup(tmp_path, open_yard)).passed


def test_movement_worlds_get_reactive_policies_and_skill_worlds_candidate_searches():
    moves = feedback_policies(list(MOVES))
    assert all(isinstance(p, ReactivePolicy) for p in moves) and len(moves) == 4 + 2 * 2
    assert ReactivePolicy(f"'{MOVES[0]}'; after a failure '{MOVES[1]}', after two '{MOVES[3]}'", (MOVES[0],),
                          (MOVES[1], MOVES[3])) in moves
    skills = feedback_policies(["find a Mug", "find a Mug_2", "pick up the Mug", "pick up the Mug_2",
                                "put down the object in hand"])
    assert {p.kinds for p in skills if isinstance(p, CandidateSearch)} == {
        ("find a ",), ("pick up the ",), ("find a ", "pick up the "), ("pick up the ", "find a ")}


class Shelf(Env):
    """Boxes ``Box``, ``Box_2`` ... and one ``Lamp``: opening the task's box solves it; opening another fails."""

    name = "shelf"

    def __init__(self, resolution: int = 64, multi_view: bool = False, task_file: str = "", **_: Any) -> None:
        self.task: Task | None = None

    @classmethod
    def load_tasks(cls, task_file: str = "", **_: Any) -> list[Task]:
        return [Task(**t) for t in json.loads(Path(task_file).read_text())]

    def reset(self, task: Task, seed: int) -> Observation:
        self.task = task
        return Observation(text="")

    def action_space(self) -> DiscreteActionSpace:
        return DiscreteActionSpace(actions=("open the Lamp", "open the Box", "open the Box_2", "open the Box_3",
                                            "open the Box_4", "look around the room"))

    def step(self, action: Any) -> StepResult:
        assert self.task is not None
        hit = self.action_space().actions[int(action)] == f"open the {self.task.metadata['box']}"
        return StepResult(observation=Observation(text=""), action_success=hit, feedback="", done=hit,
                          task_success=hit)

    def prompt_parts(self) -> PromptParts:
        return PromptParts(role="You open boxes.")


def test_trying_the_next_candidate_after_a_failure_is_caught(tmp_path):
    tasks = [{"id": f"t{i}", "subset": "base", "instruction": "Open the box with the key.",
              "metadata": {"box": box}} for i, box in enumerate(["Box", "Box_2", "Box_3", "Box_4"] * 3)]
    (tmp_path / "shelf.json").write_text(json.dumps(tasks))
    params = {"task_file": str(tmp_path / "shelf.json")}
    setup = AuditSetup(env_name="shelf", env_cls=Shelf, tasks=Shelf.load_tasks(**params), max_steps=10,
                       max_invalid_actions=10, env_params=params)
    res = probe_feedback_policies(setup)
    # the instruction names a box, so the boxes come before the lamp, and four tries find every box
    assert not res.passed and res.rows[0]["success"] == "100.0 %" and "next candidate" in res.value
    setup = AuditSetup(env_name="shelf", env_cls=Shelf, tasks=Shelf.load_tasks(**params), max_steps=10,
                       max_invalid_actions=2, env_params=params)  # two failed tries end the episode
    rows = {r["policy"]: r for r in probe_feedback_policies(setup).rows}
    assert rows["'open the ...' on each candidate, next after a failure"]["success"] == "50.0 %"


def test_an_audit_of_another_task_set_draws_its_fresh_form_at_that_difficulty(tmp_path):
    classic = yard_tasks([[4, 4], [3, 4]], wall=[])
    hard = yard_tasks([[4, 3], [2, 4], [3, 3]], wall=[[0, 3]], taskset="hard")
    calls: list[dict[str, Any]] = []

    def audit_form(out: str, seed: int, per_subset: int, difficulty: str = "classic") -> None:
        calls.append({"seed": seed, "per_subset": per_subset, "difficulty": difficulty})
        Path(out).write_text(json.dumps(yard_tasks([[4, 3], [3, 4], [3, 3]], wall=[], taskset=difficulty)))

    setup = yard_setup(tmp_path, classic + hard, taskset="hard", form_generator=audit_form, parallel_repeats=10)
    assert [t.id for t in setup.tasks] == [t["id"] for t in hard]
    res = probe_parallel_forms(setup)
    assert calls == [{"seed": 2718, "per_subset": 3, "difficulty": "hard"}] and "difficulty=hard" in res.value

    def old_form(out: str, seed: int, per_subset: int) -> None:  # a world that has no difficulty knob yet
        calls.append({"seed": seed})
        Path(out).write_text(json.dumps(yard_tasks([[4, 3], [3, 4], [3, 3]], wall=[])))

    calls.clear()
    res = probe_parallel_forms(yard_setup(tmp_path, classic + hard, taskset="hard", form_generator=old_form))
    assert calls == [{"seed": 2718}] and "at the generator's default difficulty" in res.value

    def generate(out: str, seed: int, difficulty: str = "classic") -> None:  # the whole set, at a difficulty
        calls.append({"whole": seed, "difficulty": difficulty})
        Path(out).write_text(json.dumps(yard_tasks([[4, 3], [3, 4], [3, 3]], wall=[], taskset=difficulty)))

    calls.clear()
    res = probe_parallel_forms(yard_setup(tmp_path, classic + hard, taskset="hard", form_generator=old_form,
                                          generator=generate))
    assert calls == [{"whole": 2718, "difficulty": "hard"}] and "difficulty=hard" in res.value


def test_skipped_probes_are_counted_apart(tmp_path):
    setup = yard_setup(tmp_path, yard_tasks([[4, 4], [3, 4]], wall=[]), quick=True, world_probes=[])
    results = run_audit(setup, only=["closed_loop_oracle", "parallel_forms", "instruction_templates"])
    text = format_audit("yard", results, 2)
    assert [r.skipped for _, r in results] == [True, False, True]
    assert text.endswith("audit FAILED: closed_loop_oracle (0/1 probes pass, 2 skipped)")  # the yard has no expert


def test_env_spec_names_its_audit_probes_as_module_function():
    spec = EnvSpec(name="yard", entry_point="pkg.env:Yard", audit_probes="pkg.audit:probes")
    assert spec.audit_probes == "pkg.audit:probes"
    try:
        EnvSpec(name="yard", entry_point="pkg.env:Yard", audit_probes="pkg.audit.probes")
    except ValueError as exc:
        assert "package.module:function" in str(exc)
    else:
        raise AssertionError("a probe entry point without ':' must be refused")


def test_the_fetch_searches_the_places_for_the_instructions_object_and_brings_it_to_its_place():
    from eb_core.audit import FetchSearch

    names = ["find a Vase", "find a Vase_2", "find a Table", "find a SideTable", "pick up the Vase",
             "pick up the Apple", "put down the object in hand"]
    assert FetchSearch.chunks(names, "Take a vase and leave it on the side table.") == [
        ("find a Vase", "pick up the Vase", "find a SideTable", "put down the object in hand"),
        ("find a Vase_2", "pick up the Vase", "find a SideTable", "put down the object in hand")]
    rooms = ["navigate to the left counter", "navigate to the dining table", "pick up the apple", "pick up the plum",
             "place it on the left counter", "place it on the dining table"]
    chunks = FetchSearch.chunks(rooms, "I would like the plum on the dining table.")
    assert [c[0] for c in chunks] == ["navigate to the left counter", "navigate to the dining table"]
    assert {c[1:] for c in chunks} == {("pick up the plum", "navigate to the dining table",
                                        "place it on the dining table")}
    assert FetchSearch.chunks(list(MOVES), "Walk to the sofa.") == []  # no pick-up or put actions
    assert any(isinstance(p, FetchSearch) for p in feedback_policies(rooms))
