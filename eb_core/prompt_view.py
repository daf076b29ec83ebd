"""``eb prompt``: exactly what the model would receive at one planner step of one task.

``eb prompt env=navigation task=<id> [ablation=...] [step=N] [out=DIR] [other key=value ...]`` composes the
run config like ``eb run``, plays the episode with the same :func:`eb_core.episode.run_episode` and planner,
answering each of the first N planner calls with the first action of the world's expert plan, and captures
the request of planner call N (0 = the first). It writes ``prompt.txt`` (every message in order, each image
shown as a line naming its PNG), the PNGs and, when one is sent, ``schema.json`` into the output directory, and
prints the text.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

from eb_core.model import ImagePart, ModelBackend, ModelRequest, ModelResponse, TextPart, Usage

__all__ = ["PromptCapture", "capture_prompt", "cmd_prompt", "render_request"]

_USAGE = ("usage: eb prompt env=NAME task=TASK_ID [step=N] [ablation=NAME] [out=DIR] [key=value ...] "
          "(step N = the N-th planner call, 1 = the first, as the viewer's 'Planner step N')")


def _sends_schema(model: dict[str, Any], backend_cls: Any) -> bool:
    """Whether the selected model preset gets the JSON schema (as its backend would decide at run time)."""
    mode = model.get("structured_output")
    if mode is not None:
        return mode in ("json_schema", "json_object_schema") or (mode == "auto" and bool(
            model.get("supports_json_schema")))
    if model.get("backend") == "llamacpp":
        return bool(model.get("constrained", True))
    flag = model.get("supports_json_schema")
    if flag is not None:
        return bool(flag)
    # a class attribute is the backend's fixed answer; a property (LiteLLM) decides per instance from the
    # settings, and with neither setting given that is the textual format ("none")
    default = getattr(backend_cls, "supports_json_schema", False)
    return default if isinstance(default, bool) else False


class _Captured(Exception):
    """Stops the episode once the wanted request is in hand."""


class PromptCapture(ModelBackend):
    """Answers planner calls with the expert's next action until call ``step``, whose request it keeps."""

    def __init__(self, step: int, supports_images: bool = True, supports_json_schema: bool = False) -> None:
        self.step = step
        self.supports_images = supports_images
        self.supports_json_schema = supports_json_schema
        self.calls = 0
        self.request: ModelRequest | None = None
        self.env: Any = None
        self.stopped_early: str | None = None

    def start_episode(self, ctx: Any) -> None:
        self.env = ctx.env

    def complete(self, request: ModelRequest) -> ModelResponse:
        if self.calls == self.step:
            self.request = request
            raise _Captured()
        self.calls += 1
        plan = self.env.expert_plan()
        if not plan:
            reason = getattr(self.env, "expert_reason", None) or "the expert has no plan from this state"
            self.stopped_early = f"the expert stopped after {self.calls - 1} planner calls: {reason}"
            self.request = request
            raise _Captured()
        space = self.env.action_space()
        text = json.dumps({"visual_state_description": "(expert)", "reasoning_and_reflection": "(expert)",
                           "language_plan": "(expert)", "executable_plan": [space.plan_item(plan[0])]})
        return ModelResponse(text=text, usage=Usage(calls=1))


def render_request(request: ModelRequest, out_dir: Path) -> str:
    """Write the request's images as PNGs into ``out_dir`` and return its text with image lines."""
    out_dir.mkdir(parents=True, exist_ok=True)
    lines: list[str] = []
    n = 0
    for i, msg in enumerate(request.messages):
        lines.append(f"===== message {i + 1} of {len(request.messages)}: {msg.role} =====")
        for part in msg.content:
            if isinstance(part, ImagePart):
                n += 1
                name = f"image{n:02d}_{part.name or 'image'}.png"
                (out_dir / name).write_bytes(part.png)
                lines.append(f"[image {n}: {part.name or 'image'} -> {name}]")
            elif isinstance(part, TextPart):
                lines.append(part.text)
    if request.response_schema is not None:
        (out_dir / "schema.json").write_text(json.dumps(request.response_schema, indent=2))
        lines.append("===== response format: JSON schema (schema.json) =====")
    else:
        lines.append("===== response format: none sent (the answer format is in the text) =====")
    text = "\n".join(lines) + "\n"
    (out_dir / "prompt.txt").write_text(text, encoding="utf-8")
    return text


def capture_prompt(cfg: Any, registry: Any, task_id: str, step: int) -> tuple[ModelRequest, str | None]:
    """The request of planner call ``step`` for ``task_id`` under the validated config ``cfg``."""
    from eb_core.config import ConfigError
    from eb_core.episode import run_episode
    from eb_core.runner import Components, episode_seed

    comps = Components(cfg, registry)
    try:
        tasks = {t.id: t for t in comps.load_tasks()}
    except Exception as exc:  # a missing or stale task file: the plugin's message names it
        raise ConfigError(f"cannot load the tasks of env {cfg.env.name!r}: {str(exc).splitlines()[0]}") from None
    if task_id not in tasks:
        some = ", ".join(list(tasks)[:3])
        raise ConfigError(f"unknown task id {task_id!r} for env {cfg.env.name!r}; ids look like {some} "
                          f"(`eb run env={cfg.env.name} --cfg job` shows the task file)")
    model = cfg.model.model_dump()
    backend_cls = comps.backend_cls
    backend = PromptCapture(step,
                            supports_images=bool(model.get("supports_images", backend_cls.supports_images)),
                            supports_json_schema=_sends_schema(model, backend_cls))
    env = comps.make_env()
    try:
        rec = run_episode(env=env, task=tasks[task_id], seed=episode_seed(cfg.seed, task_id),
                          planner=comps.make_planner(backend), backend=backend, env_config=cfg.env,
                          augmenters=comps.augmenters)
    finally:
        env.close()
    if backend.request is None:
        if rec.status == "error":
            raise ConfigError(f"the episode failed before planner call {step}: {(rec.error or '').splitlines()[0]}")
        raise ConfigError(f"the expert finished the episode ({rec.end_reason}) after {rec.planner_steps} planner "
                          f"calls, before call {step + 1}; pick step=1..{max(1, rec.planner_steps)}")
    return backend.request, backend.stopped_early


def cmd_prompt(args: list[str]) -> int:
    from eb_core.compose import compose, validate
    from eb_core.exceptions import CliError, ConfigError
    from eb_core.plugins import PluginError, Registry

    task_id: str | None = None
    step = 1
    out: str | None = None
    overrides: list[str] = []
    for a in args:
        key, _, value = a.partition("=")
        if a in ("-h", "--help"):
            print(_USAGE)
            return 0
        if key == "task":
            task_id = value
        elif key == "step":
            if not value.isdigit() or int(value) < 1:
                raise CliError(f"step must be a whole number >= 1 (the planner call, 1 = the first, as the viewer "
                               f"counts), got {value!r}")
            step = int(value)
        elif key == "out":
            out = value
        else:
            overrides.append(a)
    if not task_id:
        raise CliError("eb prompt needs task=TASK_ID; " + _USAGE)
    cfg_dict = compose(overrides)
    cfg = validate(cfg_dict)
    try:
        registry = Registry.create()
        request, note = capture_prompt(cfg, registry, task_id, step - 1)
    except (ConfigError, PluginError) as exc:
        raise CliError(str(exc)) from None
    out_dir = Path(out) if out else Path("prompts") / cfg.env.name / cfg.ablation.name / f"{task_id}_step{step}"
    text = render_request(request, out_dir)
    sys.stdout.write(text)
    if note:
        print(f"note: {note}; this is the prompt of the call after it")
    print(f"eb prompt: wrote {out_dir / 'prompt.txt'} and the images beside it "
          f"(env={cfg.env.name}, ablation={cfg.ablation.name}, task={task_id}, planner call {step})")
    return 0
