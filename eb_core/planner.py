"""The paper's unified agent pipeline: one configurable VLM planner for every world.

Each planner call sends one user message: the env's role and action rules, the numbered action list,
``n_shot`` in-context examples, guidelines, the instruction, the history of executed actions with the world's
feedback, a reflection request and the answer format, with the image(s) before the text (or after it where
the world says so, as the original manipulation planner did). The model answers JSON with
``visual_state_description`` (not without an image), ``reasoning_and_reflection``, ``language_plan`` and
``executable_plan``, in that order (the original's generation guide).

The ablations follow the original code (``docs/design.md`` has the table "original protocol -> ours"):

* ``language_only``: no image and no scene text (the blind baseline); ``Observation.extra_prompt`` stays.
  ``text_state`` is our separate upper bound: no image, the env's symbolic ``Observation.text`` instead.
* ``multi_step_images``: the frames after the last k environment steps (the episode hands every step's
  observation to :meth:`VLMPlanner.observe`), oldest first.
* ``chat_history``: earlier turns stay as chat messages with their images; later user turns are short
  (instruction, action history, reflection request, format); the window is ``env.chat_history_window``
  messages. When the window has dropped the last full turn, the next user turn is a full one again, so the
  model always has the role and the action list in view.
* ``multi_view``: extra views are sent and the prompt says what each image is (``PromptParts.view_descriptions``).
* ``visual_icl``: the text prompt, then the world's examples with their images, then a line introducing the
  current observation and its image.

Deviation from the original, on purpose: after an unusable answer the original sent the identical
prompt again (local models then looped to the invalid-action cap). We add a line to the history that
says the previous answer could not be used and why.
"""

from __future__ import annotations

import hashlib
import io
import json
from collections import deque
from typing import Any, Protocol, runtime_checkable

import numpy as np
from PIL import Image

from eb_core.config import ConfigError, EnvConfig, PlannerConfig
from eb_core.env import ActionSpace, Observation, PromptParts, Task, VectorActionSpace
from eb_core.model import ImagePart, Message, ModelFatalError, ModelRequest, TextPart
from eb_core.parsing import ParseResult, parse_planner_output

__all__ = ["Planner", "PlannerConfigError", "VLMPlanner", "answer_fields", "encode_png", "field_descriptions",
           "response_schema"]

FIELDS = ("visual_state_description", "reasoning_and_reflection", "language_plan", "executable_plan")

_FIELD_HELP = {
    "visual_state_description": "Describe what the current image shows that matters for the task.",
    "reasoning_and_reflection": "Sum up the actions so far and the feedback the world gave; if the last action "
    "or plan failed or did not finish the task, say why; then reason about what to do next.",
    "language_plan": "The plan in plain words: one numbered step per action, each starting with the step number "
    "and the action's name.",
    "executable_plan": "The actions to execute now, in order, each with its action id and name. Never an empty "
    "list while the task is unfinished.",
}
_VECTOR_PLAN_HELP = ("The actions to execute now, in order, each a list of integers in the action format. Never "
                     "an empty list while the task is unfinished.")


def _worlds_with_visual_examples() -> str:
    """The installed worlds whose specs say they ship visual in-context examples (for an error message)."""
    try:
        from eb_core.plugins import Registry

        names = [n for n, spec in Registry.create().envs.items() if spec.visual_examples]
    except Exception:
        names = []
    return ", ".join(names) or "none installed"


@runtime_checkable
class Planner(Protocol):
    """The contract of a planner plugin (``eb_register_planners``): what :mod:`eb_core.episode` calls.

    A planner is built per episode as ``cls(planner_config, env_config, supports_json_schema=...,
    supports_images=...)``. Per episode: :meth:`reset` once, then for every planner step :meth:`build_request`,
    :meth:`record_answer` and :meth:`parse` of the model's answer; in between the episode reports what happened
    through ``observe`` and the ``record_*`` methods, which feed the next prompt's history.
    """

    last_primary_png: bytes | None
    """Optional: PNG bytes of the current primary image of the last request, so the episode saves it without
    encoding it again; None when the planner has none (the episode encodes the image itself)."""

    def reset(self, task: Task, parts: PromptParts, space: ActionSpace, obs: Observation | None = None) -> None:
        """Start an episode of ``task`` with the world's prompt parts and its action space."""

    def observe(self, obs: Observation) -> None:
        """The observation after reset and after every env step."""

    def set_action_space(self, space: ActionSpace) -> None:
        """The action space for the next request (some worlds change it as objects appear)."""

    def build_request(self, obs: Observation, seed: int | None = None) -> ModelRequest:
        """The model request of the next planner step."""

    def record_answer(self, raw_text: str) -> None:
        """The model's raw answer to the last request (kept in the chat history where enabled)."""

    def parse(self, raw_text: str) -> ParseResult:
        """The answer's fields and its valid actions, or why it cannot be used."""

    def record_action(self, env_step: int, action_name: str, action_repr: str, success: bool, feedback: str) -> None:
        """One executed action and the world's feedback."""

    def record_output_error(self, reason: str) -> None:
        """The last answer could not be used, and why."""

    def record_plan_cut(self, reason: str) -> None:
        """The last plan was cut before its end (an invalid item), and why."""


class PlannerConfigError(ConfigError, ModelFatalError):
    """An ablation the selected world cannot run (e.g. ``visual_icl`` without visual examples).

    Raised when the first episode starts; it is a :class:`ModelFatalError` too, so the runner stops the run
    with this one line instead of recording an error episode per task.
    """


def encode_png(image: np.ndarray) -> bytes:
    """PNG bytes of an RGB array (deterministic for the same pixels)."""
    buf = io.BytesIO()
    # Level 1: lossless like any level, ~4x faster to encode than the default, files ~30 % larger.
    Image.fromarray(np.ascontiguousarray(image)).save(buf, format="PNG", optimize=False, compress_level=1)
    return buf.getvalue()


def answer_fields(with_image: bool) -> list[str]:
    """The answer's fields in the original's order (no visual description without an image)."""
    return [f for f in FIELDS if with_image or f != "visual_state_description"]


def field_descriptions(space: ActionSpace, parts: PromptParts | None = None) -> dict[str, str]:
    """What each answer field must hold: ours, with the world's own wording where it gives one."""
    out = dict(_FIELD_HELP)
    if isinstance(space, VectorActionSpace):
        out["executable_plan"] = _VECTOR_PLAN_HELP
    if parts is not None:
        out.update({k: v for k, v in parts.field_descriptions.items() if k in out})
    return out


def response_schema(space: ActionSpace, language_only: bool, parts: PromptParts | None = None,
                    max_plan_length: int | None = None, empty_plan_ok: bool = True) -> dict[str, Any]:
    """JSON schema of a planner answer for ``space`` (sent where the backend supports it).

    Every field carries a ``description`` (the original's generation guide); ``language_only`` (no image)
    drops ``visual_state_description``. The schema also says what a usable answer is, so constrained
    decoding (llama.cpp grammars, vLLM/SGLang guided decoding) can only produce one: ``action_id`` is one of
    the ids of this step's action list (``enum``: llama.cpp's schema converter has no ``minimum``/``maximum``),
    ``action_name`` no longer than the longest name, the plan at most ``max_plan_length`` actions, and at
    least one where the world counts an empty plan as an output error (``empty_plan_ok=False``: Navigation;
    elsewhere an empty plan ends the episode, a legitimate answer).
    """
    fields = answer_fields(not language_only)
    help_ = field_descriptions(space, parts)
    props: dict[str, Any] = {f: {"type": "string", "description": help_[f]} for f in fields if f != "executable_plan"}
    plan_help = help_["executable_plan"]
    if max_plan_length is not None:
        plan_help += f" At most {max_plan_length} actions."
    plan: dict[str, Any] = {"type": "array", "description": plan_help, "items": _plan_item_schema(space)}
    if not empty_plan_ok:
        plan["minItems"] = 1
    if max_plan_length is not None:
        plan["maxItems"] = max_plan_length
    props["executable_plan"] = plan
    return {
        "name": "embodied_plan",
        "schema": {"type": "object", "properties": props, "required": fields, "additionalProperties": False},
    }


def _plan_item_schema(space: ActionSpace) -> dict[str, Any]:
    """The space's plan item schema, bounded to this step's valid actions where the space has named ones."""
    item = space.plan_item_schema()
    if isinstance(space, VectorActionSpace) or not len(space):
        return item
    item = {**item, "properties": dict(item["properties"])}
    if "action_id" in item["properties"]:
        item["properties"]["action_id"] = {**item["properties"]["action_id"], "enum": list(range(len(space)))}
    if "action_name" in item["properties"]:
        longest = max(len(a) for a in space.actions)
        item["properties"]["action_name"] = {**item["properties"]["action_name"], "maxLength": longest}
    return item


class VLMPlanner:
    """Builds one :class:`ModelRequest` per planner step and keeps the episode's history."""

    def __init__(self, config: PlannerConfig, env_config: EnvConfig, *, supports_json_schema: bool = False,
                 supports_images: bool = True) -> None:
        self.config = config
        self.env_config = env_config
        n = config.n_shot if config.n_shot is not None else env_config.default_n_shot
        self.n_shot = n
        self.use_schema = config.json_schema == "always" or (config.json_schema == "auto" and supports_json_schema)
        if config.answer_format == "think":  # a schema would forbid the reasoning before the JSON
            self.use_schema = False
        self.text_state = config.text_state
        # A model that takes no images runs blind unless the text-state ablation gives it the scene text.
        self.language_only = config.language_only or (not supports_images and not config.text_state)
        self.sends_images = not (self.language_only or self.text_state)
        self.visual_icl = config.visual_icl
        self.history_window = (config.history_window if config.history_window is not None
                               else env_config.chat_history_window)
        self.task: Task | None = None
        self.parts: PromptParts | None = None
        self.space: ActionSpace | None = None
        self.history: list[str] = []
        self.turns: list[tuple[Message, bool]] = []
        """Earlier chat messages (``chat_history``) with, for user turns, whether it was a full prompt."""
        self.frames: deque[np.ndarray] = deque(maxlen=config.multi_step_images)
        """Primary images after reset and after each environment step (for ``multi_step_images``)."""
        self.calls = 0
        self._pending: Message | None = None
        self._pending_full = True
        self.last_primary_png: bytes | None = None
        """PNG of the current primary image from the last request (the runner saves it instead of re-encoding)."""
        self._pngs: dict[bytes, bytes] = {}
        """PNGs of the images sent with the last request, by content digest (see :meth:`_png`)."""

    # -- episode state ------------------------------------------------------------------------

    def reset(self, task: Task, parts: PromptParts, space: ActionSpace, obs: Observation | None = None) -> None:
        if self.visual_icl and not parts.visual_examples:
            raise PlannerConfigError(
                f"ablation visual_icl needs visual in-context examples, and env {self.env_config.name!r} ships "
                f"none; worlds with visual examples: {_worlds_with_visual_examples()} (env=...), or pick another "
                f"ablation")
        self.task, self.parts, self.space = task, parts, space
        self.history.clear()
        self.turns.clear()
        self.frames.clear()
        self.calls = 0
        if obs is not None:
            self.observe(obs)

    def observe(self, obs: Observation) -> None:
        """The observation after reset or after one environment step (the frames multi_step_images sends)."""
        if obs.primary_image is not None:
            self.frames.append(obs.primary_image)

    def set_action_space(self, space: ActionSpace) -> None:
        self.space = space

    def record_action(self, env_step: int, action_name: str, action_repr: str, success: bool, feedback: str) -> None:
        line = f"Step {env_step}: {action_repr}" + ("" if action_name in action_repr else f" ({action_name})")
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
        if self.config.chat_history and self._pending is not None:
            self.turns.append((self._pending, self._pending_full))
            self.turns.append((Message(role="assistant", content=(TextPart(text=raw_text),)), False))
        self._pending = None

    # -- prompt -------------------------------------------------------------------------------

    def _examples(self) -> list[str]:
        assert self.parts is not None
        if self.visual_icl:
            return []
        pool = self.parts.examples
        if not self.sends_images and self.parts.examples_language_only is not None:
            pool = self.parts.examples_language_only
        return list(pool[: self.n_shot])

    def _format_section(self) -> str:
        assert self.space is not None
        fields = answer_fields(self.sends_images)
        help_ = field_descriptions(self.space, self.parts)
        if self.config.answer_format == "think":
            lines = ["First reason step by step between <think> and </think>. Then write your answer between "
                     "<answer> and </answer>: exactly one JSON object (no code fences), with these fields in order:"]
        elif self.use_schema:
            lines = ["Answer with one JSON object following the schema you were given, with these fields in order:"]
        else:
            lines = ["Answer with exactly one JSON object and nothing else (no code fences), with these fields "
                     "in order:"]
        for i, f in enumerate(fields):
            lines.append(f'{i + 1}. "{f}": {help_[f]}')
        if not self.use_schema:
            example_item = json.dumps(self.space.plan_item_example())
            lines.append(f"Each item of executable_plan looks like {example_item}.")
        text = "\n".join(lines)
        if self.parts and self.parts.output_notes:
            text += "\n" + self.parts.output_notes
        return text

    def _guidelines(self) -> list[str]:
        assert self.parts is not None
        blind = self.parts.guidelines_language_only if self.language_only else None
        lines = list(blind if blind is not None else self.parts.guidelines)
        lines.append(f"A plan holds at most {self.config.max_plan_length} actions; longer plans are cut.")
        if not isinstance(self.space, VectorActionSpace):
            lines.append("Use only action ids that appear in the action list, with their exact names.")
        return lines

    def _image_names(self, obs: Observation) -> list[tuple[str, str]]:
        """(key, description) of every current-observation image sent, in order."""
        if not self.sends_images or obs.primary_image is None:
            return []
        assert self.parts is not None
        desc = self.parts.view_descriptions
        out: list[tuple[str, str]] = []
        k = len(self.frames) if (self.config.multi_step_images > 1 and not self.visual_icl) else 1
        if k > 1:
            for i in range(k):
                ago = k - 1 - i
                when = "now" if ago == 0 else f"{ago} environment step{'s' if ago > 1 else ''} ago"
                out.append((f"frame-{i}", f"{desc.get(obs.primary or '', 'your view')} ({when})"))
        else:
            out.append((obs.primary or "image", desc.get(obs.primary or "", "")))
        if k == 1 and self.env_config.multi_view and not out[0][1]:
            out[0] = (out[0][0], "the main view")
        if self.env_config.multi_view:
            for name in obs.images:
                if name != obs.primary:
                    out.append((name, desc.get(name, f"the {name.replace('_', ' ')} view")))
        return out

    def _images_section(self, obs: Observation) -> str | None:
        names = self._image_names(obs)
        if not names:
            return None

        def sentence(d: str) -> str:
            d = d.strip()
            return d if d.endswith((".", "!", "?")) else d + "."

        if len(names) == 1:
            return f"## The image\nImage: {sentence(names[0][1])}" if names[0][1] else None
        lines = [f"## The images\nYou get {len(names)} images, in this order:"]
        lines += [f"Image {i + 1}: {sentence(d)}" for i, (_, d) in enumerate(names)]
        return "\n".join(lines)

    def _step_guidance(self) -> str:
        assert self.parts is not None
        return self.parts.first_step_guidance if self.calls == 0 else self.parts.later_step_guidance

    def prompt_text(self, obs: Observation, full: bool = True) -> str:
        """The text of the current user turn (``full=False``: the short chat-history turn)."""
        assert self.task is not None and self.parts is not None and self.space is not None
        p = self.parts
        sections: list[str] = []
        if full:
            blind = self.language_only
            role = p.role_language_only if blind and p.role_language_only is not None else p.role
            rules = p.action_rules_language_only if blind and p.action_rules_language_only is not None \
                else p.action_rules
            sections.append(role.strip())
            if rules:
                sections.append("## How the actions work\n" + rules.strip())
            sections.append("## Action list\n" + self.space.describe())
            examples = self._examples()
            if examples:
                sections.append("## Examples\n" + "\n\n".join(f"Example {i + 1}:\n{e.strip()}"
                                                              for i, e in enumerate(examples)))
            sections.append("## Guidelines\n" + "\n".join(f"{i + 1}. {g}" for i, g in enumerate(self._guidelines())))
        task = f"## Your task\nInstruction: {self.task.instruction}"
        if obs.extra_prompt:
            task += "\n" + obs.extra_prompt.strip()
        sections.append(task)
        if self.text_state:
            sections.append("## What you perceive\n" + (obs.text or "(no description available)"))
        images = self._images_section(obs)
        if images:
            sections.append(images)
        if self.history:
            sections.append("## What you have done so far\n" + "\n".join(self.history))
            look = "what you see now and " if self.sends_images else ""
            sections.append("## Reflect and re-plan\nLook at " + look + "the history above: say what the "
                            + ("feedback tells you and " if self.config.feedback else "")
                            + "why the last plan did not finish the task, then plan from the current state.")
        else:
            sections.append("## What you have done so far\nNothing yet: this is the first step.")
        guidance = self._step_guidance()
        if guidance:
            sections.append("## This step\n" + guidance.strip())
        sections.append("## Answer format\n" + self._format_section())
        return "\n\n".join(sections)

    def _current_images(self, obs: Observation) -> list[ImagePart]:
        self.last_primary_png = None
        if not self.sends_images:
            return []
        primary = obs.primary_image
        if primary is None:
            return []
        sent: dict[bytes, bytes] = {}
        self.last_primary_png = self._png(primary, sent)
        parts: list[ImagePart] = []
        if self.config.multi_step_images > 1 and not self.visual_icl:
            frames = list(self.frames) or [primary]
            for i, frame in enumerate(frames):
                # The newest frame is the current observation (after augmenters).
                png = self.last_primary_png if i == len(frames) - 1 else self._png(frame, sent)
                parts.append(ImagePart(png=png, name=f"frame-{i}"))
        else:
            parts.append(ImagePart(png=self.last_primary_png, name=obs.primary or "image"))
        if self.env_config.multi_view:
            for name, img in obs.images.items():
                if name != obs.primary:
                    parts.append(ImagePart(png=self._png(img, sent), name=name))
        self._pngs = sent
        return parts

    def _png(self, image: np.ndarray, sent: dict[bytes, bytes]) -> bytes:
        """PNG bytes of ``image``; the same bytes as last request's when these pixels were sent then (an action
        that changed nothing in view, the earlier frames of ``multi_step_images``): hashing the pixels costs
        ~0.4 ms, encoding a 500 px image ~10 ms."""
        arr = np.ascontiguousarray(image)
        key = hashlib.sha1(arr.data).digest() + f"{arr.shape}{arr.dtype.str}".encode()
        png = sent.get(key) or self._pngs.get(key)
        if png is None:
            png = encode_png(arr)
        sent[key] = png
        return png

    def _visual_examples(self) -> list[TextPart | ImagePart]:
        assert self.parts is not None
        out: list[TextPart | ImagePart] = [TextPart(text="## Examples with images")]
        for i, ex in enumerate(self.parts.visual_examples):
            pieces = ex.text.split("<image>")
            images = list(ex.images) if self.sends_images else []
            content: list[TextPart | ImagePart] = []
            for j, piece in enumerate(pieces):
                text = (f"Example {i + 1}:\n" if j == 0 else "") + piece.strip()
                if text.strip():
                    content.append(TextPart(text=text))
                if j < len(pieces) - 1 and images:
                    content.append(ImagePart(png=images.pop(0), name=f"example-{i + 1}"))
            content += [ImagePart(png=png, name=f"example-{i + 1}") for png in images]
            out += content
        return out

    def _window(self) -> list[tuple[Message, bool]]:
        """Earlier turns that fit in the window together with the current user message."""
        turns = list(self.turns)
        if self.history_window is not None:
            turns = turns[-(self.history_window - 1):] if self.history_window > 1 else []
        while turns and turns[0][0].role != "user":
            turns.pop(0)
        return turns

    def build_request(self, obs: Observation, seed: int | None = None) -> ModelRequest:
        earlier = self._window() if self.config.chat_history else []
        full = not any(is_full for _, is_full in earlier)
        text = self.prompt_text(obs, full=full)
        images = self._current_images(obs)
        content: list[Any] = []
        if self.visual_icl:
            content.append(TextPart(text=text))
            if full:  # a short chat-history turn does not repeat the examples
                content += self._visual_examples()
            if images:
                content.append(TextPart(text="Below is your current observation. Plan for it, learning from the "
                                             "strategy and the examples above, and answer only with the JSON "
                                             "object."))
                content += images
        elif self.parts is not None and self.parts.text_before_images:
            content = [TextPart(text=text), *images]
        else:
            content = [*images, TextPart(text=text)]
        current = Message(role="user", content=tuple(content))
        self._pending, self._pending_full = current, full
        self.calls += 1
        assert self.space is not None
        return ModelRequest(
            messages=tuple([m for m, _ in earlier] + [current]),
            response_schema=(response_schema(self.space, not self.sends_images, self.parts,
                                             self.config.max_plan_length,
                                             empty_plan_ok=self.env_config.empty_plan_ends)
                             if self.use_schema else None),
            seed=seed,
        )

    def parse(self, raw_text: str) -> ParseResult:
        assert self.space is not None
        return parse_planner_output(raw_text, self.space, self.config.max_plan_length,
                                    answer_format=self.config.answer_format)
