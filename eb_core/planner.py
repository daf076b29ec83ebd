"""The paper's unified agent pipeline: one configurable VLM planner for every world.

Each planner call sends (images first, then text): the env's role and action rules, the numbered
action list, ``n_shot`` in-context examples, guidelines, the instruction, the history of executed
actions with the world's feedback, and the answer format. The model answers JSON with
``visual_state_description``, ``reasoning_and_reflection``, ``language_plan`` and ``executable_plan``.

Deviation from the original, on purpose: after an unusable answer the original sent the identical
prompt again (local models then looped to the invalid-action cap). We add a line to the history that
says the previous answer could not be used and why.
"""

from __future__ import annotations

import io
from collections import deque
from typing import Any

import numpy as np
from PIL import Image

from eb_core.config import EnvConfig, PlannerConfig
from eb_core.env import ActionSpace, Observation, PromptParts, Task, VectorActionSpace
from eb_core.model import ImagePart, Message, ModelRequest, TextPart
from eb_core.parsing import ParseResult, parse_planner_output

__all__ = ["VLMPlanner", "encode_png", "response_schema"]

_FIELD_HELP = {
    "visual_state_description": "what the image shows right now that matters for the task",
    "reasoning_and_reflection": "your reasoning about the task, what the history and feedback tell you, "
    "and what went wrong before if anything did",
    "language_plan": "the next steps in plain words",
    "executable_plan": "the actions to execute now, in order",
}


def encode_png(image: np.ndarray) -> bytes:
    """PNG bytes of an RGB array (deterministic for the same pixels)."""
    buf = io.BytesIO()
    # Level 1: lossless like any level, ~4x faster to encode than the default, files ~30 % larger.
    Image.fromarray(np.ascontiguousarray(image)).save(buf, format="PNG", optimize=False, compress_level=1)
    return buf.getvalue()


def response_schema(space: ActionSpace, language_only: bool) -> dict[str, Any]:
    """JSON schema of a planner answer for ``space`` (sent where the backend supports it)."""
    fields = [f for f in _FIELD_HELP if not (language_only and f == "visual_state_description")]
    props: dict[str, Any] = {f: {"type": "string"} for f in fields if f != "executable_plan"}
    props["executable_plan"] = {"type": "array", "items": space.plan_item_schema()}
    return {
        "name": "embodied_plan",
        "schema": {"type": "object", "properties": props, "required": fields, "additionalProperties": False},
    }


class VLMPlanner:
    """Builds one :class:`ModelRequest` per planner step and keeps the episode's history."""

    def __init__(self, config: PlannerConfig, env_config: EnvConfig, *, supports_json_schema: bool = False,
                 supports_images: bool = True) -> None:
        self.config = config
        self.env_config = env_config
        n = config.n_shot if config.n_shot is not None else env_config.default_n_shot
        self.n_shot = n
        self.use_schema = config.json_schema == "always" or (config.json_schema == "auto" and supports_json_schema)
        self.language_only = config.language_only or not supports_images
        self.task: Task | None = None
        self.parts: PromptParts | None = None
        self.space: ActionSpace | None = None
        self.history: list[str] = []
        self.turns: deque[tuple[str, str]] = deque(maxlen=config.history_window)
        self.frames: deque[np.ndarray] = deque(maxlen=config.multi_step_images)
        self._pending_user_text = ""
        self.last_primary_png: bytes | None = None
        """PNG of the current primary image from the last request (the runner saves it instead of re-encoding)."""

    # -- episode state ------------------------------------------------------------------------

    def reset(self, task: Task, parts: PromptParts, space: ActionSpace) -> None:
        self.task, self.parts, self.space = task, parts, space
        self.history.clear()
        self.turns.clear()
        self.frames.clear()

    def set_action_space(self, space: ActionSpace) -> None:
        self.space = space

    def record_action(self, env_step: int, action_name: str, action_repr: str, success: bool, feedback: str) -> None:
        line = f"Step {env_step}: {action_repr} ({action_name})"
        if self.config.feedback:
            line += f" -> {'succeeded' if success else 'failed'}. Feedback: {feedback}"
        self.history.append(line)

    def record_output_error(self, reason: str) -> None:
        self.history.append(
            f"Your previous answer could not be used ({reason}). Answer with one JSON object in the required "
            f"format, choosing action ids from the list."
        )

    def record_plan_cut(self, reason: str) -> None:
        self.history.append(f"Note: {reason}.")

    def record_answer(self, raw_text: str) -> None:
        if self.config.chat_history:
            self.turns.append((self._pending_user_text, raw_text))

    # -- prompt -------------------------------------------------------------------------------

    def _format_section(self) -> str:
        assert self.space is not None
        fields = [f for f in _FIELD_HELP if not (self.language_only and f == "visual_state_description")]
        if self.use_schema:
            text = "Answer with one JSON object following the schema you were given (fields: " + ", ".join(fields) + ")."
        else:
            import json

            lines = ["Answer with exactly one JSON object and nothing else. Its fields:"]
            for f in fields:
                lines.append(f'- "{f}": {_FIELD_HELP[f]}')
            example_item = json.dumps(self.space.plan_item_example())
            lines.append(f"Each item of executable_plan looks like {example_item}.")
            text = "\n".join(lines)
        if self.parts and self.parts.output_notes:
            text += "\n" + self.parts.output_notes
        return text

    def _guidelines(self) -> list[str]:
        assert self.parts is not None
        lines = list(self.parts.guidelines)
        lines.append(f"A plan holds at most {self.config.max_plan_length} actions; longer plans are cut.")
        if not isinstance(self.space, VectorActionSpace):
            lines.append("Use only action ids that appear in the action list, with their exact names.")
        return lines

    def prompt_text(self, obs: Observation) -> str:
        assert self.task is not None and self.parts is not None and self.space is not None
        p = self.parts
        sections = [p.role.strip()]
        if p.action_rules:
            sections.append("## How the actions work\n" + p.action_rules.strip())
        sections.append("## Action list\n" + self.space.describe())
        examples = list(p.examples[: self.n_shot])
        if examples:
            sections.append("## Examples\n" + "\n\n".join(f"Example {i + 1}:\n{e.strip()}" for i, e in enumerate(examples)))
        sections.append("## Guidelines\n" + "\n".join(f"{i + 1}. {g}" for i, g in enumerate(self._guidelines())))
        task = f"## Your task\nInstruction: {self.task.instruction}"
        if obs.extra_prompt:
            task += "\n" + obs.extra_prompt.strip()
        sections.append(task)
        if self.language_only:
            sections.append("## What you perceive\n" + (obs.text or "(no description available)"))
        elif self.config.multi_step_images > 1 and len(self.frames) > 1:
            sections.append(f"The images show your last {len(self.frames)} views, oldest first; the last one is now.")
        if self.history:
            sections.append("## What you have done so far\n" + "\n".join(self.history))
        else:
            sections.append("## What you have done so far\nNothing yet: this is the first step.")
        sections.append("## Answer format\n" + self._format_section())
        return "\n\n".join(sections)

    def build_request(self, obs: Observation, seed: int | None = None) -> ModelRequest:
        text = self.prompt_text(obs)
        self._pending_user_text = text
        content: list[Any] = []
        self.last_primary_png = None
        if not self.language_only:
            primary = obs.primary_image
            if primary is not None:
                self.last_primary_png = encode_png(primary)
                self.frames.append(primary)
                if self.config.multi_step_images > 1:
                    for i, frame in enumerate(self.frames):
                        png = self.last_primary_png if i == len(self.frames) - 1 else encode_png(frame)
                        content.append(ImagePart(png=png, name=f"frame-{i}"))
                else:
                    content.append(ImagePart(png=self.last_primary_png, name=obs.primary or "image"))
            if self.env_config.multi_view:
                for name, img in obs.images.items():
                    if name != obs.primary:
                        content.append(ImagePart(png=encode_png(img), name=name))
        content.append(TextPart(text=text))
        messages: list[Message] = []
        if self.config.chat_history:
            for user_text, answer in self.turns:
                messages.append(Message(role="user", content=(TextPart(text=user_text),)))
                messages.append(Message(role="assistant", content=(TextPart(text=answer),)))
        messages.append(Message(role="user", content=tuple(content)))
        assert self.space is not None
        return ModelRequest(
            messages=tuple(messages),
            response_schema=response_schema(self.space, self.language_only) if self.use_schema else None,
            seed=seed,
        )

    def parse(self, raw_text: str) -> ParseResult:
        assert self.space is not None
        return parse_planner_output(raw_text, self.space, self.config.max_plan_length)
