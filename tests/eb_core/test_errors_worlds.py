"""A scripted plan on a real world (Habitat, geometry mode) commits errors and the runner labels them."""

import json
import re

import pytest

from eb_core import ModelBackend, ModelBackendSpec, ModelResponse, Usage, hookimpl

# each answer: the action names of a plan (looked up in the prompt's action list; an unknown name gets an id
# past the list's end), or a raw string
SCRIPT = [["pick up the plum"], ["pick up the plum"], ["pick up the giraffe"], "no json at all", []]


class NamedPlanBackend(ModelBackend):
    """Answers SCRIPT in order, turning action names into ids with the prompt's ``action id i: name`` lines."""

    def __init__(self, **_: object) -> None:
        self.i = 0

    def complete(self, request):
        text = request.messages[-1].text
        ids = {name: int(i) for i, name in re.findall(r"^action id (\d+): (.+)$", text, flags=re.MULTILINE)}
        answer = SCRIPT[min(self.i, len(SCRIPT) - 1)]
        self.i += 1
        if isinstance(answer, list):
            plan = [{"action_id": ids.get(n, len(ids) + 7), "action_name": n} for n in answer]
            answer = json.dumps({"visual_state_description": "a plum and a giraffe", "reasoning_and_reflection": "",
                                 "language_plan": "; ".join(n for n in answer), "executable_plan": plan})
        return ModelResponse(text=answer, usage=Usage(calls=1))


@hookimpl
def eb_register_model_backends():
    return [ModelBackendSpec(name="named-plan", entry_point="test_errors_worlds:NamedPlanBackend",
                             description="scripted plans by action name (tests)")]


def test_a_scripted_habitat_episode_is_labelled(tmp_path, monkeypatch):
    monkeypatch.delenv("EB_DISABLE_PLUGIN_AUTOLOAD", raising=False)
    monkeypatch.delenv("EB_PLUGINS", raising=False)
    import test_errors_worlds

    from eb_core.compose import compose
    from eb_core.config import validate_config
    from eb_core.plugins import Registry
    from eb_core.runner import run

    registry = Registry.create()
    if "habitat" not in registry.envs:
        pytest.skip("eb-habitat is not installed")
    cfg_dict = compose(["env=habitat", "env.params.render=false", "tasks=[base-00]", "runner.quiet=true"])
    cfg_dict["model"] = {"name": "named-plan", "backend": "named-plan"}
    cfg_dict["runner"]["expert_labels"] = True
    summary = run(validate_config(cfg_dict), tmp_path, plugins=[test_errors_worlds])
    rec = json.loads((tmp_path / "episodes.jsonl").read_text().splitlines()[0])
    assert rec["end_reason"] == "empty_plan" and not rec["success"]
    counts = rec["error_counts"]
    # the plum lies elsewhere: picking it up from the start fails (twice), skipping the expert's navigation;
    # the failures carry the world's reason when it gives one ("precondition": not near), else "unclassified"
    reasons = [a.get("failure") for line in (tmp_path / "episodes" / "base-00" / "steps.jsonl").read_text().splitlines()
               for a in json.loads(line)["actions"]]
    assert len(reasons) == 2 and reasons[0] == reasons[1] and reasons[0] in (None, "precondition")
    assert counts["precondition_error" if reasons[0] else "failed_action"] == 2
    assert counts["repetition"] == 1 and counts["missing_step"] == 2
    assert counts["hallucinated_object"] == 1  # "pick up the giraffe": no giraffe in the scene's action list
    assert counts["format_error"] == 1 and counts["premature_stop"] == 1
    assert summary["overall"]["error_analysis"]["categories"]["premature_stop"]["episode_rate"] == 1.0


@pytest.mark.parametrize("world", ["manipulation", "navigation"])
def test_a_hard_taskset_run_can_be_relabelled_from_replayed_images(tmp_path, monkeypatch, capsys, world):
    """eb report --errors replays a run in its world: a taskset=hard run builds the env from env.params alone
    (the task set goes to the task loaders, not to the Env's constructor)."""
    monkeypatch.delenv("EB_DISABLE_PLUGIN_AUTOLOAD", raising=False)
    monkeypatch.delenv("EB_PLUGINS", raising=False)
    from eb_core.compose import compose
    from eb_core.config import validate_config
    from eb_core.plugins import Registry
    from eb_core.report import load_run
    from eb_core.runner import run

    registry = Registry.create()
    if world not in registry.envs or "hard" not in registry.envs[world].tasksets:
        pytest.skip(f"eb-{world} with a hard task set is not installed")
    cfg = validate_config(compose([f"env={world}", "taskset=hard", "model=oracle", "limit=1", "runner.quiet=true"]))
    run(cfg, tmp_path)
    capsys.readouterr()
    relabelled = load_run(tmp_path, relabel_errors=True)["overall"]
    assert relabelled["episodes"] == 1 and relabelled["success_rate"] == 1.0
    assert relabelled["error_analysis"]["categories"]  # labelled ...
    assert "replay" not in capsys.readouterr().err  # ... from a replay that ran and matched the record


def test_a_task_changed_since_the_run_is_not_replayed(tmp_path, monkeypatch, capsys):
    """A hard task set regenerated after a run (session 8: EB-Habitat v6 after the players' v5 runs) gives the
    same id another scene: replaying it judged the descriptions against objects the model never saw (a "rubik's
    cube" nowhere in the scene). Such an episode keeps its stored lists; an unchanged one is replayed."""
    monkeypatch.delenv("EB_DISABLE_PLUGIN_AUTOLOAD", raising=False)
    monkeypatch.delenv("EB_PLUGINS", raising=False)
    from eb_core.compose import compose
    from eb_core.config import validate_config
    from eb_core.errors import load_steps
    from eb_core.errors.replay import replay_run
    from eb_core.plugins import Registry
    from eb_core.records import RunFiles, episode_dir_name
    from eb_core.runner import run

    if "manipulation" not in Registry.create().envs:
        pytest.skip("eb-manipulation is not installed")
    cfg = validate_config(compose(["env=manipulation", "model=oracle", "limit=1", "runner.quiet=true"]))
    run(cfg, tmp_path)
    capsys.readouterr()
    rec = RunFiles(tmp_path).load_episodes()[0]
    stored = [dict(s, visible_objects=[{"name": "object 99", "type": "stored marker"}])
              for s in load_steps(tmp_path / "episodes" / episode_dir_name(*rec.key))]
    same = replay_run(tmp_path, [rec], {rec.key: stored})[rec.key]
    assert same[0]["visible_objects"][0]["name"] != "object 99"  # replayed: what the world shows
    assert "changed" not in capsys.readouterr().err
    other = rec.model_copy(update={"instruction": rec.instruction + " (an older version of this task)"})
    kept = replay_run(tmp_path, [other], {rec.key: stored})[rec.key]
    assert [s["visible_objects"] for s in kept] == [s["visible_objects"] for s in stored]
    assert f"the task set has changed since {tmp_path}" in capsys.readouterr().err


def test_a_scene_changed_under_the_same_instruction_is_not_replayed(tmp_path, monkeypatch, capsys):
    """A regenerated task can keep its id and its wording and still stand in another scene (a new draw of the same
    template). The run's manifest holds the digest of the tasks it ran (scenes included); when the installed tasks
    no longer match it, nothing is replayed and the labels use the lists stored at run time."""
    from pathlib import Path

    monkeypatch.delenv("EB_DISABLE_PLUGIN_AUTOLOAD", raising=False)
    monkeypatch.delenv("EB_PLUGINS", raising=False)
    from eb_core.compose import compose
    from eb_core.config import validate_config
    from eb_core.errors import load_steps
    from eb_core.errors.replay import replay_run
    from eb_core.plugins import Registry
    from eb_core.records import RunFiles, episode_dir_name
    from eb_core.runner import run

    if "manipulation" not in Registry.create().envs:
        pytest.skip("eb-manipulation is not installed")
    from eb_manipulation.tasks import DEFAULT_TASK_FILE

    doc = json.loads(Path(DEFAULT_TASK_FILE).read_text(encoding="utf-8"))
    task_file = tmp_path / "tasks.json"
    task_file.write_text(json.dumps(doc), encoding="utf-8")
    run_dir = tmp_path / "run"
    cfg = validate_config(compose(["env=manipulation", "model=oracle", "limit=1", "runner.quiet=true",
                                   f"+env.params.task_file={task_file}"]))
    run(cfg, run_dir)
    capsys.readouterr()
    rec = RunFiles(run_dir).load_episodes()[0]
    stored = [dict(s, visible_objects=[{"name": "object 99", "type": "stored marker"}])
              for s in load_steps(run_dir / "episodes" / episode_dir_name(*rec.key))]
    assert replay_run(run_dir, [rec], {rec.key: stored})[rec.key][0]["visible_objects"][0]["name"] != "object 99"
    # the same id and instruction, another scene: one object moved by 3 cm
    first = next(t for t in doc["tasks"] if t["id"] == rec.task_id)
    first["metadata"]["objects"][0]["x"] += 0.03
    task_file.write_text(json.dumps(doc), encoding="utf-8")
    kept = replay_run(run_dir, [rec], {rec.key: stored})[rec.key]
    assert [s["visible_objects"] for s in kept] == [s["visible_objects"] for s in stored]
    assert "digest differs from the manifest's" in capsys.readouterr().err
