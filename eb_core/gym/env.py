"""One EmbodiedBench world as a Gymnasium environment (``gymnasium.make("EB/Navigation-v0", ...)``).

``obs_mode="prompt"`` plays the episode with :class:`eb_core.episode.EpisodeDriver`, the code ``eb run`` uses:
the observation is the driver's next model request (the planner's prompt under the composed config and
ablation), the action is the model's raw answer, which the driver parses and executes by the runner's rules
(plans up to the first failure, output errors, empty plans, step budget and invalid cap). ``obs_mode="raw"``
steps the world one action at a time for classic RL, with the same step budget and invalid cap.

Everything a step can go wrong on (an env bug, a closed world) ends the episode with ``truncated=True`` and
``info["error"]``; the world is then rebuilt on the next ``reset``. ``step`` never raises on any action.
"""

from __future__ import annotations

import io
import string
import traceback
from collections.abc import Mapping, Sequence
from functools import lru_cache
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from eb_core.env import DiscreteActionSpace, Env, Observation, Task
from eb_core.gym.rewards import TERMS, reward_weights, total_reward
from eb_core.model import ImagePart, ModelBackend, ModelRequest, ModelResponse, TextPart, Usage

__all__ = ["CHARSET", "IMAGE_PLACEHOLDER", "EBEnv", "request_observation"]

IMAGE_PLACEHOLDER = "<image>"
"""Where an image of the request stands in the observation's prompt text (images in ``obs["images"]``, in order)."""

#: Characters of the Text spaces: printable ASCII plus the Latin-1 letters and typographic punctuation the
#: worlds' prompts use. Any other character in a prompt is replaced by ``?`` (``info["replaced_chars"]`` counts).
CHARSET = frozenset(string.printable + "".join(chr(c) for c in range(0xA0, 0x180))
                    + "".join(chr(c) for c in (*range(0x2010, 0x2028), *range(0x2030, 0x2040)))
                    + "\u2190\u2191\u2192\u2193\u2212\u00d7")
MAX_TEXT = 200_000

_END_TERMINATED = {"success", "done", "empty_plan"}


class _AnswerBackend(ModelBackend):
    """Stands for the trainer's model: the gym env hands its answers to the episode driver itself."""

    supports_images = True
    supports_json_schema = False

    def complete(self, request: ModelRequest) -> ModelResponse:  # pragma: no cover - never called
        raise RuntimeError("the gym env's answers come from step(action)")


@lru_cache(maxsize=16)
def _compose(world: str, overrides: tuple[str, ...]) -> Any:
    from eb_core.compose import compose, group_options, hydra_context, validate
    from eb_core.exceptions import UserError

    extra: list[str] = []
    if not any(o.split("=", 1)[0].lstrip("+~") == "model" for o in overrides):
        # the gym env makes no model calls; any installed model preset fills the config's model group
        with hydra_context():
            models = group_options("model")
        if models and "oracle" not in models:
            extra = [f"model={models[0]}"]
    try:
        return validate(compose([f"env={world}", *extra, *overrides]))
    except UserError as exc:
        raise ValueError(str(exc)) from None


def _registry() -> Any:
    """The plugin registry of this process, made once per plugin selection (``EB_PLUGINS``,
    ``EB_DISABLE_PLUGIN_AUTOLOAD``): the many environments of a vector env's worker share it."""
    import os

    from eb_core.plugins import AUTOLOAD_OFF_ENV_VAR, PLUGINS_ENV_VAR

    return _registry_for(os.environ.get(PLUGINS_ENV_VAR), os.environ.get(AUTOLOAD_OFF_ENV_VAR))


@lru_cache(maxsize=4)
def _registry_for(_plugins: str | None, _autoload_off: str | None) -> Any:
    from eb_core.plugins import Registry

    return Registry.create()


@lru_cache(maxsize=16)
def _test_tasks(world: str, overrides: tuple[str, ...], subset: str | None, _plugins: int) -> tuple[Task, ...]:
    """The shipped tasks (of ``subset``), loaded once per process and shared by its environments (read only)."""
    from eb_core.components import Components

    tasks = Components(_compose(world, overrides), _registry()).load_tasks()
    if subset is not None:
        tasks = [t for t in tasks if t.subset == subset]
        if not tasks:
            raise ValueError(f"env {world!r} has no test tasks in subset {subset!r}")
    return tuple(tasks)


def _decode_png(png: bytes) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.uint8)


def _clean(text: str) -> tuple[str, int]:
    bad = sum(1 for c in text if c not in CHARSET)
    if bad:
        text = "".join(c if c in CHARSET else "?" for c in text)
    return text[:MAX_TEXT], bad


def request_observation(request: ModelRequest) -> tuple[str, list[np.ndarray]]:
    """The prompt text of a model request (each message headed by its role when there are several, each
    image as :data:`IMAGE_PLACEHOLDER`) and its images decoded, in order."""
    chunks: list[str] = []
    images: list[np.ndarray] = []
    several = len(request.messages) > 1
    for msg in request.messages:
        if several:
            chunks.append(f"[{msg.role}]")
        for part in msg.content:
            if isinstance(part, ImagePart):
                chunks.append(IMAGE_PLACEHOLDER)
                images.append(_decode_png(part.png))
            elif isinstance(part, TextPart):
                chunks.append(part.text)
    return "\n".join(chunks), images


def _step_info(rec: Any, failed: int) -> dict[str, Any]:
    """The ``info`` entries of a prompt-mode step from its step record (None: the episode ended without one)."""
    acts = rec.actions if rec is not None else []
    format_error = rec.error if rec is not None else None
    plan_error = rec.plan_error if rec is not None else None
    format_ok = format_error is None
    cut = plan_error is not None
    nothing_valid = format_ok and cut and not acts
    parsed = rec.parsed if rec is not None else None
    return {
        "plan": None if parsed is None else parsed.executable_plan,
        "executed_actions": [a.action for a in acts],
        "executed_action_names": [a.action_name for a in acts],
        "action_valid": format_ok and not cut and failed == 0 and not nothing_valid,
        "format_ok": format_ok,
        "format_error": format_error,
        "plan_error": plan_error,
        "feedback": acts[-1].feedback if acts else (format_error or plan_error or ""),
    }


def _jsonable(v: Any) -> Any:
    return list(v) if isinstance(v, tuple) else v


class EBEnv(gymnasium.Env):
    """A world of EmbodiedBench as a Gymnasium env.

    Args:
        world: registered env name (``navigation``, ``alfred``, ``habitat``, ``manipulation``, a plugin's).
        split: ``test`` (the shipped tasks) or a generated split (``train``, ``val``) of worlds that have one.
        obs_mode: ``prompt`` (what ``eb run`` sends the model; the action is the answer text) or ``raw``
            (``Dict(image, text)``; ``Discrete`` or ``MultiDiscrete`` actions).
        reward: a preset (``success``, ``progress``, ``shaped``) or a dict of term weights.
        overrides: Hydra overrides as for ``eb run`` (``ablation=language_only``, ``planner.answer_format=think``,
            ``env.resolution=300``, ``env.params.render=false``...).
        subset: only tasks of this subset (test split).
        expert_labels: put the world's expert's next action in ``info["expert_action"]`` after every step.
        raw_action_n: size of the ``Discrete`` raw action space (default: the first task's action count;
            ids beyond the current episode's list are invalid actions).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 4}

    def __init__(self, world: str, split: str = "test", obs_mode: str = "prompt",
                 reward: str | Mapping[str, float] = "progress", overrides: Sequence[str] = (),
                 subset: str | None = None, expert_labels: bool = True, raw_action_n: int | None = None,
                 render_mode: str | None = None) -> None:
        from eb_core.components import Components

        if obs_mode not in ("prompt", "raw"):
            raise ValueError(f"obs_mode must be 'prompt' or 'raw', got {obs_mode!r}")
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        self.world, self.split, self.obs_mode, self.render_mode = world, split, obs_mode, render_mode
        self.weights = reward_weights(reward)
        self.expert_labels = bool(expert_labels)
        self.cfg = _compose(world, tuple(overrides))
        self.comps = Components(self.cfg, _registry())
        self.env_cls: type[Env] = self.comps.env_cls
        params = self.comps.task_params()  # env.params, and taskset= when it is not the classic set
        if split == "test":
            self._tasks: Sequence[Task] | None = _test_tasks(world, tuple(overrides), subset, id(_registry()))
        else:
            self._tasks = None
            self.env_cls.split_tasks(split, 0, 1, **params)  # one clear error for an unknown split, up front
        self.env: Env | None = None
        self._driver: Any = None
        self._last_obs: Any = None
        self._last_image: np.ndarray | None = None
        res = self.cfg.env.resolution
        img = spaces.Box(0, 255, shape=(res, res, 3), dtype=np.uint8)
        text = spaces.Text(max_length=MAX_TEXT, min_length=0, charset=CHARSET)
        if obs_mode == "prompt":
            self.observation_space = spaces.Dict({"prompt": text, "images": spaces.Sequence(img)})
            self.action_space = spaces.Text(max_length=MAX_TEXT, min_length=0, charset=CHARSET)
        else:
            self.observation_space = spaces.Dict({"image": img, "text": text})
            world_env = self._world()
            try:  # fixed-list worlds know their space before a reset: no rendering (no GL context) here
                space = world_env.action_space()
            except Exception:
                world_env.reset(self.task_at(0), 0)
                space = world_env.action_space()
            if isinstance(space, DiscreteActionSpace):
                self.action_space = spaces.Discrete(int(raw_action_n or len(space)))
            else:
                low, high = np.array(space.low), np.array(space.high)
                self.action_space = spaces.MultiDiscrete(high - low + 1, start=low)

    # -- tasks -------------------------------------------------------------------------------------

    def task_at(self, index: int) -> Task:
        if self._tasks is not None:
            return self._tasks[index % len(self._tasks)]
        return self.env_cls.split_tasks(self.split, index, 1, **self.comps.task_params())[0]

    def _task_by_id(self, task_id: str) -> Task:
        if self._tasks is not None:
            for t in self._tasks:
                if t.id == task_id:
                    return t
            raise ValueError(f"unknown task_id {task_id!r} in split 'test' of {self.world!r}; ids look like "
                             f"{self._tasks[0].id!r}")
        digits = task_id.rsplit("-", 1)[-1]
        if digits.isdigit():
            task = self.task_at(int(digits))
            if task.id == task_id:
                return task
        raise ValueError(f"unknown task_id {task_id!r} in split {self.split!r} of {self.world!r}; ids look like "
                         f"{self.task_at(0).id!r}")

    def _world(self) -> Env:
        if self.env is None:
            self.env = self.comps.make_env()
        return self.env

    def _rebuild(self) -> None:
        if self.env is not None:
            try:
                self.env.close()
            except Exception:
                pass
        self.env = None

    # -- gymnasium API -----------------------------------------------------------------------------

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        from eb_core.components import episode_seed

        super().reset(seed=seed)
        options = options or {}
        if options.get("task_id") is not None:
            task = self._task_by_id(str(options["task_id"]))
        elif seed is not None:
            task = self.task_at(int(seed))
        else:
            task = self.task_at(int(self.np_random.integers(0, 2**31 - 1)))
        self.task = task
        self.world_seed = episode_seed(self.cfg.seed, task.id)
        self._close_driver()
        env = self._world()
        self._progress, self._steps, self._invalid, self._success = 0.0, 0, 0, False
        self._done = False
        self._dist = None
        if self.obs_mode == "prompt":
            obs = self._reset_prompt(env, task)
        else:
            observation = env.reset(task, self.world_seed)
            for aug in self.comps.augmenters:
                observation = aug(observation)
            self._feedback = ""
            obs = self._raw_obs(observation)
        self._dist = self._distance()
        info = {"task_id": task.id, "subset": task.subset, "instruction": task.instruction, "split": self.split,
                "world_seed": self.world_seed, **self._expert()}
        return obs, info

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        try:
            if self._done:
                raise RuntimeError("step() after the episode ended: call reset()")
            if self.obs_mode == "prompt":
                return self._step_prompt(action)
            return self._step_raw(action)
        except Exception as exc:  # an env bug or a dead world: the episode ends, the world is rebuilt
            self._done = True
            self._close_driver()
            self._rebuild()
            terms = {k: 0.0 for k in TERMS}
            info = {"error": f"{type(exc).__name__}: {exc}", "traceback": traceback.format_exc(limit=8),
                    "reward_terms": terms, "action_valid": False, "format_ok": False, "task_success": False,
                    "progress": self._progress, "feedback": "", "plan": None, "executed_actions": []}
            return self._last_obs, 0.0, False, True, info

    def render(self) -> np.ndarray | None:
        return self._last_image

    def close(self) -> None:
        self._close_driver()
        self._rebuild()

    # -- prompt mode -------------------------------------------------------------------------------

    def _reset_prompt(self, env: Env, task: Task) -> Any:
        from eb_core.episode import EpisodeDriver, EpisodeOptions

        backend = _AnswerBackend()
        planner = self.comps.make_planner(backend)
        # no step files: the driver keeps the step records in memory (driver.steps)
        self._driver = EpisodeDriver(env=env, task=task, seed=self.world_seed, planner=planner, backend=backend,
                                     env_config=self.cfg.env,
                                     options=EpisodeOptions(save_images=False, augmenters=self.comps.augmenters))
        self._steps_seen = 0
        request = self._driver.next_request()
        if request is None:
            rec = self._driver.record
            self._driver = None
            self._rebuild()
            raise RuntimeError(f"the episode of task {task.id} ended at reset: {(rec.error or rec.end_reason)}")
        return self._prompt_obs(request)

    def _prompt_obs(self, request: ModelRequest) -> dict[str, Any]:
        text, images = request_observation(request)
        text, self._replaced = _clean(text)
        self._request = request
        if images:
            self._last_image = images[-1]
        self._last_obs = {"prompt": text, "images": tuple(images)}
        return self._last_obs

    def _step_prompt(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        text = action if isinstance(action, str) else (action.decode("utf-8", "replace")
                                                       if isinstance(action, bytes) else str(action))
        driver = self._driver
        driver.submit(ModelResponse(text=text, usage=Usage(calls=1)))
        steps = driver.steps
        rec = steps[-1] if len(steps) > self._steps_seen else None
        self._steps_seen = len(steps)
        acts = rec.actions if rec is not None else []
        format_error = rec.error if rec is not None else None
        plan_error = rec.plan_error if rec is not None else None
        failed = sum(1 for a in acts if not a.success)
        progress = acts[-1].progress if acts else self._progress
        self._steps += len(acts)
        if driver.done:
            obs, success, progress, terminated, truncated, error = self._end_prompt_episode(driver, progress)
        else:
            obs = self._prompt_obs(driver.next_request())
            success, terminated, truncated, error = False, False, False, None
        info = self._finish_info(progress, success, failed + (plan_error is not None), int(format_error is not None))
        info.update(_step_info(rec, failed))
        info["replaced_chars"] = self._replaced
        if error is not None:
            info["error"] = error
        if driver.done:
            info["end_reason"] = driver.record.end_reason
        return obs, info.pop("_reward"), terminated, truncated, info

    def _end_prompt_episode(self, driver: Any, progress: float) -> tuple[Any, bool, float, bool, bool, str | None]:
        """The episode's record has come: observation, success, progress, terminated, truncated, error line."""
        record = driver.record
        self._done = True
        error = None
        if record.status == "error":
            error = (record.error or "").splitlines()[0]
            self._rebuild()
        self._driver = None
        terminated = record.end_reason in _END_TERMINATED
        return (self._last_obs, bool(record.success), 1.0 if record.success else progress, terminated,
                not terminated, error)

    def _close_driver(self) -> None:
        if self._driver is not None:
            try:
                self._driver.close()
            except Exception:
                pass
            self._driver = None

    # -- raw mode ----------------------------------------------------------------------------------

    def _raw_obs(self, observation: Observation) -> dict[str, Any]:
        res = self.cfg.env.resolution
        image = observation.primary_image
        if image is None:
            image = np.zeros((res, res, 3), dtype=np.uint8)
        self._last_image = image
        text = f"Instruction: {self.task.instruction}"
        if observation.extra_prompt:
            text += "\n" + observation.extra_prompt
        if self._feedback:
            text += f"\nFeedback: {self._feedback}"
        text, self._replaced = _clean(text)
        self._last_obs = {"image": np.ascontiguousarray(image, dtype=np.uint8), "text": text}
        return self._last_obs

    def _step_raw(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        env = self._world()
        space = env.action_space()
        ecfg = self.cfg.env
        try:
            if isinstance(space, DiscreteActionSpace):
                act: Any = space.parse_plan_item(int(np.asarray(action).reshape(-1)[0]))
            else:
                act = space.parse_plan_item([int(v) for v in np.asarray(action).reshape(-1)])
        except Exception as exc:  # out of this episode's list
            act = None
            bad = str(exc)
        invalid = 0
        executed: list[Any] = []
        terminated = False
        success = False
        if act is None:
            invalid = 1
            self._feedback = f"invalid action: {bad}"
            if ecfg.output_error_uses_step:
                self._steps += 1
            progress = self._progress
            obs = self._last_obs
            obs = self._raw_obs_text_only()
        else:
            result = env.step(act)
            self._steps += 1
            executed.append(_jsonable(act))
            self._feedback = result.feedback
            progress = max(0.0, min(1.0, result.progress))
            if not result.action_success:
                invalid = 1
            observation = result.observation
            for aug in self.comps.augmenters:
                observation = aug(observation)
            obs = self._raw_obs(observation)
            if result.done:
                terminated = True
                success = bool(result.task_success)
                if success:
                    progress = 1.0
        self._invalid += invalid
        cap = ecfg.max_invalid_actions
        truncated = not terminated and (self._steps >= ecfg.max_steps or (cap is not None and self._invalid >= cap))
        self._done = terminated or truncated
        info = self._finish_info(progress, success, invalid, 0)
        info.update({"plan": executed or None, "executed_actions": executed,
                     "executed_action_names": [space.name_of(a) for a in executed],
                     "action_valid": invalid == 0, "format_ok": True, "feedback": self._feedback,
                     "replaced_chars": self._replaced})
        return obs, info.pop("_reward"), terminated, truncated, info

    def _raw_obs_text_only(self) -> dict[str, Any]:
        obs = dict(self._last_obs)
        text = f"Instruction: {self.task.instruction}\nFeedback: {self._feedback}"
        obs["text"], self._replaced = _clean(text)
        self._last_obs = obs
        return obs

    # -- shared ------------------------------------------------------------------------------------

    def _distance(self) -> float | None:
        try:
            d = getattr(self.env, "distance_to_goal", None)
            if callable(d):
                d = d()
        except Exception:
            return None
        return None if d is None else float(d)

    def _expert(self) -> dict[str, Any]:
        if not self.expert_labels or self._done or self.env is None:
            return {}
        from eb_core.episode import _expert_label

        label = _expert_label(self.env, self.env.action_space())
        if label.get("expert_action") is None:  # absent, not None: vector envs batch it into a numeric array
            label.pop("expert_action", None)
        return label

    def _finish_info(self, progress: float, success: bool, invalid: int, format_error: int) -> dict[str, Any]:
        gained = progress - self._progress
        self._progress = progress
        new_success = success and not self._success
        self._success = self._success or success
        dist = None if self._done and self.env is None else self._distance()
        moved = (self._dist - dist) if (self._dist is not None and dist is not None) else 0.0
        self._dist = dist
        terms = {"success": 1.0 if new_success else 0.0, "progress": float(gained), "invalid": float(invalid),
                 "format": float(format_error), "distance": float(moved)}
        info: dict[str, Any] = {"reward_terms": terms, "_reward": total_reward(terms, self.weights),
                                "progress": float(progress), "task_success": bool(self._success),
                                "task_id": self.task.id, "steps": self._steps}
        if dist is not None:
            info["distance_to_goal"] = dist
        info.update(self._expert())
        return info
