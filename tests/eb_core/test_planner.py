"""The original evaluation protocol in the planner: one test per ablation comparing prompts with and without it,
the answer schema, step accounting, expert labels. Played on the corridor fixture (real numpy images)."""

import io
import json

import numpy as np
import pytest
from PIL import Image

from eb_core_testutil import make_config
from eb_core.env import VisualExample
from eb_core.episode import run_episode
from eb_core.model import ImagePart, ModelFatalError, TextPart
from eb_core.planner import PlannerConfigError, VLMPlanner, encode_png, response_schema
from fixture_plugin import CorridorEnv, ScriptedBackend

SCENE_TEXT = "You are at cell"
EXTRA = "object 1: [3, 0, 0]"


def plan(*ids):
    return json.dumps({"visual_state_description": "v", "reasoning_and_reflection": "r", "language_plan": "l",
                       "executable_plan": [{"action_id": i, "action_name": "x"} for i in ids]})


def _png(color: int) -> bytes:
    return encode_png(np.full((8, 8, 3), color, np.uint8))


class RichCorridor(CorridorEnv):
    """The corridor with an extra prompt line per observation and configurable prompt parts."""

    def __init__(self, parts=None, **kw):
        super().__init__(**kw)
        self.parts_over = parts or {}

    def _obs(self):
        return super()._obs().model_copy(update={"extra_prompt": EXTRA})

    def prompt_parts(self):
        base = super().prompt_parts().model_copy(update={
            "examples": ("TEXT-EXAMPLE-A", "TEXT-EXAMPLE-B"),
            "view_descriptions": {"top": "the corridor seen from above", "side": "the corridor upside down"},
        })
        return base.model_copy(update=self.parts_over)


def play(answers, parts=None, schema=False, tmp_path=None, expert_labels=False, task_index=0, **over):
    cfg = make_config(**over)
    env = RichCorridor(parts=parts, resolution=64, multi_view=cfg.env.multi_view)
    backend = ScriptedBackend(answers=answers)
    planner = VLMPlanner(cfg.planner, cfg.env, supports_json_schema=schema)
    rec = run_episode(env=env, task=CorridorEnv.load_tasks()[task_index], seed=1, planner=planner, backend=backend,
                      env_config=cfg.env, step_dir=tmp_path, expert_labels=expert_labels)
    return rec, backend


def sections(text):
    """The prompt's sections by heading (the first one, the role, under '')."""
    out = {}
    for i, chunk in enumerate(text.split("\n\n## ")):
        head, _, body = chunk.partition("\n") if i else ("", "", chunk)
        out[head] = body
    return out


def images(msg):
    return [p for p in msg.content if isinstance(p, ImagePart)]


def pixel_pos(png: bytes, length=8) -> int:
    """The agent's cell in a corridor image (its red column)."""
    img = np.asarray(Image.open(io.BytesIO(png)))
    cell = img.shape[1] // length
    return int(np.argmax([img[0, i * cell, 0] for i in range(length)]))


# -- language_only / text_state ---------------------------------------------------------------------


def test_language_only_is_blind_and_changes_only_images_examples_and_the_visual_field():
    _, base = play([plan(1, 1)])
    _, blind = play([plan(1, 1)], parts={"examples_language_only": ("BLIND-EXAMPLE",)}, planner__language_only=True)
    b, l = base.requests[0].messages[-1], blind.requests[0].messages[-1]
    assert images(b) and not images(l)
    assert SCENE_TEXT not in l.text and SCENE_TEXT not in b.text
    assert EXTRA in l.text  # the per-observation extra prompt stays (manipulation's coordinates)
    sb, sl = sections(b.text), sections(l.text)
    changed = {k for k in sb.keys() | sl.keys() if sb.get(k) != sl.get(k)}
    assert changed == {"Examples", "Answer format", "The image"}  # the image's description goes with it
    assert "BLIND-EXAMPLE" in sl["Examples"] and "TEXT-EXAMPLE-A" not in sl["Examples"]
    assert '"visual_state_description"' in sb["Answer format"] and "visual_state_description" not in sl["Answer format"]
    # every later prompt too: the scene text never appears
    _, blind3 = play([plan(0), "garbage", plan(1, 1, 1)], planner__language_only=True)
    assert all(SCENE_TEXT not in r.messages[-1].text and not images(r.messages[-1]) for r in blind3.requests)


def test_language_only_without_a_language_only_example_set_keeps_the_examples():
    _, blind = play([plan(1, 1)], planner__language_only=True)
    assert "TEXT-EXAMPLE-A" in blind.requests[0].messages[-1].text


def test_text_state_adds_the_scene_text_and_drops_the_image():
    _, base = play([plan(1, 1)])
    _, ts = play([plan(1, 1)], planner__text_state=True)
    b, t = base.requests[0].messages[-1], ts.requests[0].messages[-1]
    assert not images(t)
    sb, st = sections(b.text), sections(t.text)
    assert st["What you perceive"] == "You are at cell 0; the goal is cell 2."
    changed = {k for k in sb.keys() | st.keys() if sb.get(k) != st.get(k)}
    assert changed == {"What you perceive", "Answer format", "The image"}


def test_language_only_and_text_state_exclude_each_other():
    from eb_core.config import ConfigError

    with pytest.raises(ConfigError, match="exclude each other"):
        make_config(planner__language_only=True, planner__text_state=True)


# -- multi_step_images ------------------------------------------------------------------------------


def test_multi_step_frames_follow_env_steps_not_planner_calls():
    # near-0: start 0, goal 2. Calls: step right (pos 1); garbage (no step); step left (pos 0); left again
    # (a wall bump, still a step: pos 0); then walk.
    _, backend = play([plan(1), "garbage", plan(0), plan(0), plan(1, 1)], planner__multi_step_images=3)
    frames = [[pixel_pos(p.png) for p in images(r.messages[-1])] for r in backend.requests]
    assert frames[0] == [0]
    assert frames[1] == [0, 1]
    assert frames[2] == [0, 1]  # the unusable answer moved nothing: no new frame
    assert frames[3] == [0, 1, 0]
    assert frames[4] == [1, 0, 0]  # only the last 3 kept
    text = backend.requests[3].messages[-1].text
    assert "Image 1: the corridor seen from above (2 environment steps ago)." in text
    assert "Image 3: the corridor seen from above (now)." in text


def test_multi_step_first_call_equals_the_default_prompt():
    _, base = play([plan(1, 1)])
    _, ms = play([plan(1, 1)], planner__multi_step_images=3)
    assert base.requests[0].messages[-1].text == ms.requests[0].messages[-1].text


def test_a_plan_of_several_steps_gives_the_frame_after_each_step():
    _, backend = play([plan(0, 0, 1), plan(1, 1)], task_index=1, planner__multi_step_images=3,
                      env__replan_on_failure=False)  # near-1: start 1; left, wall, right
    assert [pixel_pos(p.png) for p in images(backend.requests[1].messages[-1])] == [0, 0, 1]


# -- text_before_images / multi_view --------------------------------------------------------------------


def test_text_before_images_puts_the_text_first():
    _, a = play([plan(1, 1)])
    _, b = play([plan(1, 1)], parts={"text_before_images": True})
    assert isinstance(a.requests[0].messages[-1].content[0], ImagePart)
    assert isinstance(b.requests[0].messages[-1].content[0], TextPart)
    assert a.requests[0].messages[-1].text == b.requests[0].messages[-1].text


def test_multi_view_says_what_each_image_is():
    _, base = play([plan(1, 1)])
    _, mv = play([plan(1, 1)], env__multi_view=True)
    b, m = base.requests[0].messages[-1], mv.requests[0].messages[-1]
    assert [p.name for p in images(m)] == ["top", "side"]
    sb, sm = sections(b.text), sections(m.text)
    assert sb["The image"] == "Image: the corridor seen from above."
    assert sm["The images"].splitlines()[1:] == ["Image 1: the corridor seen from above.",
                                                 "Image 2: the corridor upside down."]
    changed = {k for k in sb.keys() | sm.keys() if sb.get(k) != sm.get(k)}
    assert changed == {"The image", "The images"}


# -- chat_history ---------------------------------------------------------------------------------------


def test_chat_history_keeps_images_and_sends_short_later_turns():
    _, base = play([plan(0), plan(1), plan(1, 1)])
    _, ch = play([plan(0), plan(1), plan(1, 1)], planner__chat_history=True)
    req = ch.requests[2]
    assert [m.role for m in req.messages] == ["user", "assistant", "user", "assistant", "user"]
    assert req.messages[0] == ch.requests[0].messages[-1]  # the first full turn, with its image
    assert all(len(images(m)) == 1 for m in req.messages if m.role == "user")
    assert req.messages[1].text == plan(0)
    short = req.messages[-1].text
    assert "## Action list" not in short and "You walk along a corridor." not in short and "## Examples" not in short
    assert "Instruction: walk to cell 2" in short and "## What you have done so far" in short
    assert "## Reflect and re-plan" in short and "## Answer format" in short
    # the first call is the default prompt; later full prompts are not sent again
    assert ch.requests[0].messages[-1].text == base.requests[0].messages[-1].text
    assert sections(short)["What you have done so far"] == sections(base.requests[2].messages[-1].text)[
        "What you have done so far"]


def test_chat_history_window_counts_messages_and_a_full_turn_returns_when_dropped():
    answers = [plan(0)] * 6
    _, ch = play(answers, planner__chat_history=True, env__chat_history_window=5, env__max_invalid_actions=None,
                 env__max_steps=6)
    roles = [[m.role for m in r.messages] for r in ch.requests]
    assert [len(r) for r in roles] == [1, 3, 5, 5, 5, 5]
    full = ["## Action list" in r.messages[-1].text for r in ch.requests]
    # call 4's window would drop the first (full) turn: it is full again; then short while one is in view
    assert full == [True, False, False, True, False, False]
    assert all(any("## Action list" in m.text for m in r.messages if m.role == "user") for r in ch.requests)


def test_chat_history_window_null_keeps_the_whole_episode():
    _, ch = play([plan(0)] * 5, planner__chat_history=True, env__max_invalid_actions=None, env__max_steps=5)
    assert [len(r.messages) for r in ch.requests] == [1, 3, 5, 7, 9]


# -- visual_icl ----------------------------------------------------------------------------------------


VIS = (VisualExample(text="Walk right.<image>Then again.", images=(_png(10), _png(20))),
       VisualExample(text="Reach the goal.", images=(_png(30),)))


def test_visual_icl_order_text_examples_intro_current_image():
    _, base = play([plan(1, 1)])
    _, vi = play([plan(1, 1)], parts={"visual_examples": VIS}, planner__visual_icl=True)
    content = vi.requests[0].messages[-1].content
    kinds = [("img:" + p.name) if isinstance(p, ImagePart) else p.text.split("\n")[0][:20] for p in content]
    assert kinds == ["You walk along a cor", "## Examples with ima", "Example 1:", "img:example-1", "Then again.",
                     "img:example-1", "Example 2:", "img:example-2", "Below is your curren", "img:top"]
    assert [p.png for p in content if isinstance(p, ImagePart)][:3] == [_png(10), _png(20), _png(30)]
    sb, sv = sections(base.requests[0].messages[-1].text), sections(content[0].text)
    assert set(sb) - set(sv) == {"Examples"} and all(sb[k] == sv[k] for k in sv)


def test_visual_icl_on_a_world_without_visual_examples_is_one_config_error():
    # the worlds named come from the installed specs (EnvSpec.visual_examples); core tests see the fixture only
    with pytest.raises(PlannerConfigError, match="visual_icl.*worlds with visual examples: none installed") as exc:
        play([plan(1, 1)], planner__visual_icl=True)
    assert isinstance(exc.value, ModelFatalError) and "\n" not in str(exc.value)


# -- step guidance ----------------------------------------------------------------------------------------


def test_first_and_later_step_guidance():
    _, b = play([plan(0), plan(1, 1)], parts={"first_step_guidance": "FIRST-G", "later_step_guidance": "LATER-G"})
    first, later = b.requests[0].messages[-1].text, b.requests[1].messages[-1].text
    assert sections(first)["This step"] == "FIRST-G" and "LATER-G" not in first
    assert sections(later)["This step"] == "LATER-G" and "FIRST-G" not in later


# -- answer format and schema ------------------------------------------------------------------------------


def _all_props(schema):
    for name, prop in schema.get("properties", {}).items():
        yield name, prop
        if prop.get("type") == "array":
            yield from _all_props(prop["items"])
        yield from _all_props(prop)


def test_schema_describes_every_field_in_the_original_order():
    env = RichCorridor()
    space = env.action_space()
    s = response_schema(space, language_only=False, max_plan_length=20)["schema"]
    assert list(s["properties"]) == s["required"] == ["visual_state_description", "reasoning_and_reflection",
                                                      "language_plan", "executable_plan"]
    props = list(_all_props(s))
    assert {n for n, _ in props} >= {"action_id", "action_name", "executable_plan"}
    assert all(p.get("description") for _, p in props)
    assert "Never an empty list" in s["properties"]["executable_plan"]["description"]
    assert "At most 20" in s["properties"]["executable_plan"]["description"]
    blind = response_schema(space, language_only=True)["schema"]
    assert blind["required"] == ["reasoning_and_reflection", "language_plan", "executable_plan"]


def test_schema_allows_only_usable_plans_of_this_step():
    env = RichCorridor()
    space = env.action_space()
    n = len(space)
    item = response_schema(space, language_only=True)["schema"]["properties"]["executable_plan"]["items"]
    assert item["properties"]["action_id"]["enum"] == list(range(n))  # the listed ids, nothing else
    assert item["properties"]["action_name"]["maxLength"] == max(len(a) for a in space.actions)
    # an empty plan is an output error only where it does not end the episode (Navigation)
    nav = response_schema(space, True, max_plan_length=5, empty_plan_ok=False)["schema"]["properties"]
    assert nav["executable_plan"]["minItems"] == 1 and nav["executable_plan"]["maxItems"] == 5
    other = response_schema(space, True)["schema"]["properties"]["executable_plan"]
    assert "minItems" not in other and "maxItems" not in other
    # the planner sends the world's rule and this step's action list
    for ends, want in ((True, None), (False, 1)):
        _, b = play([plan(1, 1)], schema=True, env__empty_plan_ends=ends, planner__max_plan_length=4)
        sent = b.requests[0].response_schema["schema"]["properties"]["executable_plan"]
        assert sent.get("minItems") == want and sent["maxItems"] == 4
        assert sent["items"]["properties"]["action_id"]["enum"] == list(range(n))


def test_vector_schema_items_are_described():
    from eb_core.env import VectorActionSpace

    space = VectorActionSpace(names=("x", "y", "z", "roll", "pitch", "yaw", "gripper"), low=(0,) * 7,
                              high=(99, 99, 99, 119, 119, 119, 1))
    s = response_schema(space, language_only=False)["schema"]
    assert all(p.get("description") for _, p in _all_props(s))


def test_text_prompt_asks_for_the_schema_fields_in_order_with_the_same_descriptions():
    for schema in (True, False):
        _, b = play([plan(1, 1)], schema=schema, parts={"field_descriptions": {"language_plan": "WORLD-WORDS"}})
        req = b.requests[0]
        fmt = sections(req.messages[-1].text)["Answer format"]
        listed = [ln.split('"')[1] for ln in fmt.splitlines() if ln[:1].isdigit()]
        assert listed == ["visual_state_description", "reasoning_and_reflection", "language_plan", "executable_plan"]
        assert '3. "language_plan": WORLD-WORDS' in fmt
        if schema:
            props = req.response_schema["schema"]["properties"]
            assert list(props) == listed and props["language_plan"]["description"] == "WORLD-WORDS"
            for ln in fmt.splitlines()[1:5]:
                name = ln.split('"')[1]
                assert ln.endswith(props[name]["description"].split(" At most")[0])
        else:
            assert req.response_schema is None and "no code fences" in fmt


# -- step accounting -----------------------------------------------------------------------------------------


def test_output_errors_use_a_step_where_the_world_says_so():
    rec, b = play(["garbage"], env__output_error_uses_step=True, env__max_invalid_actions=None, env__max_steps=6)
    assert (rec.env_steps, rec.output_errors, rec.planner_steps, rec.end_reason) == (0, 6, 6, "max_steps")


def test_output_errors_use_no_step_elsewhere_and_the_invalid_cap_ends_the_episode():
    rec, b = play(["garbage", "garbage", plan(1), "garbage", "garbage", "garbage"],
                  env__output_error_uses_step=False, env__max_invalid_actions=4, env__max_steps=6)
    assert (rec.env_steps, rec.output_errors, rec.invalid_actions, rec.end_reason) == (1, 4, 4, "invalid_cap")
    assert rec.planner_steps == 5


def test_output_errors_without_a_step_or_a_cap_still_end():
    rec, _ = play(["garbage"], env__output_error_uses_step=False, env__max_invalid_actions=None, env__max_steps=5)
    assert (rec.env_steps, rec.output_errors, rec.end_reason) == (0, 5, "invalid_cap")


def test_empty_plan_in_a_world_where_it_does_not_end_uses_a_step_like_the_original_random_action():
    rec, _ = play([plan(), plan(1, 1)], env__empty_plan_ends=False)
    assert rec.success and rec.output_errors == 1 and rec.invalid_actions == 0 and rec.empty_plan


# -- expert labels -----------------------------------------------------------------------------------------


def test_expert_labels_log_the_experts_first_action_from_the_state_before(tmp_path):
    play([plan(0, 1, 1, 1)], tmp_path=tmp_path, expert_labels=True, env__replan_on_failure=False)
    acts = [a for ln in (tmp_path / "steps.jsonl").read_text().splitlines() for a in json.loads(ln)["actions"]]
    # near-0: start 0 goal 2. Before each action the expert says "step right" (1); the wall bump changes nothing.
    assert [a["action"] for a in acts] == [0, 1, 1]
    assert [a["expert_action"] for a in acts] == [1, 1, 1]
    assert acts[0]["expert_action_name"] == "step right"


def test_expert_labels_off_by_default_and_none_with_a_reason(tmp_path):
    play([plan(1, 1)], tmp_path=tmp_path)
    acts = json.loads((tmp_path / "steps.jsonl").read_text().splitlines()[0])["actions"]
    assert "expert_action" not in acts[0]

    class NoExpert(RichCorridor):
        expert_reason = "no expert for this corridor"

        def expert_plan(self):
            return None

    cfg = make_config()
    env = NoExpert(resolution=64)
    run_episode(env=env, task=CorridorEnv.load_tasks()[0], seed=1, planner=VLMPlanner(cfg.planner, cfg.env),
                backend=ScriptedBackend(answers=[plan(1, 1)]), env_config=cfg.env, step_dir=tmp_path / "b",
                expert_labels=True)
    a = json.loads((tmp_path / "b" / "steps.jsonl").read_text().splitlines()[0])["actions"][0]
    assert a["expert_action"] is None and a["expert_reason"] == "no expert for this corridor"


def test_visual_icl_with_chat_history_shows_the_examples_once():
    _, b = play([plan(0), plan(1, 1)], parts={"visual_examples": VIS}, planner__visual_icl=True,
                planner__chat_history=True)
    req = b.requests[1]
    example_images = [p for m in req.messages for p in images(m) if p.name.startswith("example-")]
    assert len(example_images) == 3  # the first turn's, not repeated in the short turn
    assert [p.name for p in images(req.messages[-1])] == ["top"]


def test_multi_view_without_a_primary_description_and_with_full_sentences():
    _, mv = play([plan(1, 1)], env__multi_view=True,
                 parts={"view_descriptions": {"side": "The second image is the corridor upside down."}})
    assert sections(mv.requests[0].messages[-1].text)["The images"].splitlines()[1:] == [
        "Image 1: the main view.", "Image 2: The second image is the corridor upside down."]


def test_an_invalid_first_item_without_a_cap_still_ends_where_errors_use_steps():
    bad = json.dumps({"executable_plan": [{"action_id": 9, "action_name": "x"}]})
    rec, _ = play([bad], env__output_error_uses_step=True, env__max_invalid_actions=None, env__max_steps=4)
    assert (rec.env_steps, rec.invalid_actions, rec.output_errors, rec.planner_steps) == (0, 4, 0, 4)
    rec, _ = play([bad], env__output_error_uses_step=False, env__max_invalid_actions=3, env__max_steps=4)
    assert (rec.env_steps, rec.invalid_actions, rec.planner_steps, rec.end_reason) == (0, 3, 3, "invalid_cap")
