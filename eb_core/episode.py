"""One episode: the paper's execution rules around a planner, a model backend and an env.

Rules (from the paper, with our documented deviation on output errors):

* Run the plan in order, cut to the remaining step budget.
* Stop at the first failed action and re-plan (``env.replan_on_failure``; manipulation runs the whole plan).
* An empty plan ends the episode (``env.empty_plan_ends``); elsewhere it counts as an output error.
* A plan item that is not a valid action cuts the plan there; if nothing is left it is an invalid action
  (using a step of the budget where ``env.output_error_uses_step``, so every episode ends).
* An unusable answer is an output error: it counts as an invalid action and the next prompt says why it was
  rejected. Where ``env.output_error_uses_step`` (Navigation, Manipulation) it also uses one step of the
  budget (the original executed a random action instead); elsewhere (ALFRED, Habitat) it uses none, as the
  original, and the invalid cap bounds the episode (``env.max_steps`` output errors when there is no cap).
* End at ``env.max_steps`` or at ``env.max_invalid_actions`` invalid actions.
* ``expert_labels``: before each executed action, the world's expert plan from that state is asked for and its
  first action logged as ``expert_action`` (None and ``expert_reason`` when the expert has none).
"""

from __future__ import annotations

import json
import time
import traceback
from collections.abc import Callable, Generator, Sequence
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, Literal

from eb_core.config import EnvConfig
from eb_core.env import Env, Observation, StepResult, Task
from eb_core.events import EpisodeStartEvent, StepEndEvent
from eb_core.model import (
    EpisodeContext,
    ImagePart,
    ModelBackend,
    ModelBudgetExceeded,
    ModelFatalError,
    ModelRequest,
    ModelResponse,
    Usage,
)
from eb_core.planner import Planner, encode_png
from eb_core.records import ActionRecord, EndReason, EpisodeRecord, StepRecord

__all__ = ["BudgetGuard", "EpisodeDriver", "EpisodeOptions", "play", "run_episode"]


class BudgetGuard:
    """Adds up the cost of model calls (across processes when given a shared value) and enforces the cap."""

    def __init__(self, max_cost_usd: float | None, shared: Any = None) -> None:
        self.max_cost_usd = max_cost_usd
        self.shared = shared
        self.local = 0.0

    def add(self, cost: float) -> None:
        if self.shared is not None:
            with self.shared.get_lock():
                self.shared.value += cost
                total = self.shared.value
        else:
            self.local += cost
            total = self.local
        if self.max_cost_usd is not None and total >= self.max_cost_usd:
            raise ModelBudgetExceeded(f"model.max_cost_usd={self.max_cost_usd} reached (spent {total:.4f} USD)")

    def exhausted(self) -> bool:
        total = self.shared.value if self.shared is not None else self.local
        return self.max_cost_usd is not None and total >= self.max_cost_usd


#: World ``StepResult.info`` keys copied into each action's record for error analysis (docs/error_analysis.md).
_INFO_KEYS_RECORDED = ("distance_to_goal", "path_distance", "wrong_target", "position")
"""World state a step's ``info`` carries that the step record keeps (``position``: where the agent stands, for the
viewer's map of a walk)."""
FINAL_IMAGE_PREFIX = "final_"
"""``final_<view>.png``: the state the episode ended in (the viewer's last picture; no model saw it)."""


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, tuple):
        return list(obj)
    return obj


def _expert_label(env: Env, space: Any) -> dict[str, Any]:
    """The first action of the world's expert plan from the current state, for ``expert_labels``."""
    try:
        plan = env.expert_plan()
    except Exception as exc:  # an expert bug must not end the agent's episode
        return {"expert_action": None, "expert_reason": f"the expert raised {type(exc).__name__}: {exc}"}
    if not plan:
        reason = getattr(env, "expert_reason", None) or (
            "the expert has no plan from this state" if plan is None else "the expert plan is empty")
        return {"expert_action": None, "expert_reason": reason}
    first = plan[0]
    try:
        name = space.name_of(first)
    except Exception:
        name = None
    return {"expert_action": _jsonable(first), "expert_action_name": name}


@dataclass(frozen=True)
class EpisodeOptions:
    """How an episode is recorded and observed, apart from what it is played on (env, task, seed, planner,
    backend, env config). The same options for every episode of a run; ``repeat`` and ``step_dir`` per episode."""

    step_dir: Path | None = None
    """Where ``steps.jsonl`` and the step PNGs go; None writes no files (the steps stay in memory)."""
    save_images: bool = True
    augmenters: Sequence[Callable[[Observation], Observation]] = ()
    budget: BudgetGuard | None = None
    hook: Any = None
    """The plugin manager's hook relay, for the episode-start and step-end events; None sends none."""
    run_dir: str = ""
    expert_labels: bool = False
    repeat: int = 0


def _options(options: EpisodeOptions | None, kwargs: dict[str, Any]) -> EpisodeOptions:
    """``options``, or one built from the keyword arguments (the form callers before the options object used)."""
    if options is not None:
        if kwargs:
            raise TypeError(f"pass either options= or the option keywords, not both ({', '.join(kwargs)})")
        return options
    unknown = sorted(set(kwargs) - {f.name for f in fields(EpisodeOptions)})
    if unknown:
        raise TypeError(f"unknown episode option(s) {', '.join(unknown)}; allowed: "
                        f"{', '.join(f.name for f in fields(EpisodeOptions))}")
    return EpisodeOptions(**kwargs)


class _Episode:
    """The state of one episode and the paper's rules over it; :meth:`flow` is the generator the driver runs."""

    def __init__(self, env: Env, task: Task, seed: int, planner: Planner, backend: ModelBackend,
                 env_config: EnvConfig, opts: EpisodeOptions) -> None:
        self.env, self.task, self.seed, self.planner, self.backend = env, task, seed, planner, backend
        self.cfg, self.opts = env_config, opts
        self.steps: list[StepRecord] = []
        self.usage = Usage()
        self.env_steps = self.planner_steps = self.invalid = self.output_errors = 0
        self.charged = 0  # answers that executed nothing but use a step of the budget (where uses_step)
        self.progress, self.success, self.empty_plan, self.done = 0.0, False, False, False
        self.end_reason: EndReason = "max_steps"
        self.uses_step = env_config.output_error_uses_step
        # Output errors that use no step are bounded by the invalid cap, or by max_steps of them without one.
        self.invalid_cap = env_config.max_invalid_actions
        if self.invalid_cap is None and not self.uses_step:
            self.invalid_cap = env_config.max_steps
        self.obs: Observation | None = None

    # -- counters -------------------------------------------------------------------------------------

    def budget_left(self) -> int:
        return self.cfg.max_steps - self.env_steps - self.charged

    def capped(self) -> bool:
        return self.invalid_cap is not None and self.invalid >= self.invalid_cap

    def augment(self, o: Observation) -> Observation:
        for aug in self.opts.augmenters:
            o = aug(o)
        return o

    def output_error(self, reason: str, count_invalid: bool = True) -> None:
        self.output_errors += 1
        if count_invalid or not self.uses_step:
            self.invalid += 1
        if self.uses_step:
            self.charged += 1
        self.planner.record_output_error(reason)

    # -- the episode ----------------------------------------------------------------------------------

    def flow(self) -> Generator[ModelRequest, ModelResponse, EpisodeRecord]:
        """Yields each model request, receives its response (or the call's exception, thrown in) and returns
        the record."""
        started = time.perf_counter()
        opts = self.opts
        steps_file = None
        if opts.step_dir is not None:
            opts.step_dir.mkdir(parents=True, exist_ok=True)
            steps_file = open(opts.step_dir / "steps.jsonl", "w", encoding="utf-8")
        if opts.hook is not None:
            opts.hook.eb_on_episode_start(event=EpisodeStartEvent(
                run_dir=opts.run_dir, task_id=self.task.id, subset=self.task.subset,
                instruction=self.task.instruction, seed=self.seed))
        status: Literal["ok", "error"] = "ok"
        error: str | None = None
        try:
            self.begin()
            while not self.done and self.budget_left() > 0:
                if self.capped():
                    self.end_reason = "invalid_cap"
                    break
                head, request = self.prepare_step()
                response = yield request  # the only blocking point: the model call, made by the caller
                step = self.handle_answer(head, response)
                self.steps.append(step)
                if steps_file is not None:
                    steps_file.write(step.to_json_line())
                    steps_file.flush()
            if not self.done and self.end_reason == "max_steps" and self.capped():
                self.end_reason = "invalid_cap"
            self._save_final_image()
        except (ModelFatalError, ModelBudgetExceeded):
            raise
        except Exception as exc:  # a model that stayed unreachable, or an env bug: recorded, the run goes on
            status, self.end_reason = "error", "error"
            error = f"{type(exc).__name__}: {exc}\n{traceback.format_exc(limit=20)}"
        finally:
            if steps_file is not None:
                steps_file.close()
        return self.record(status, error, time.perf_counter() - started)

    def begin(self) -> None:
        self.obs = self.augment(self.env.reset(self.task, self.seed))
        self.planner.reset(self.task, self.env.prompt_parts(), self.env.action_space())
        self.planner.observe(self.obs)
        self.backend.start_episode(EpisodeContext(env=self.env, task=self.task, seed=self.seed,
                                                  run_dir=self.opts.run_dir or None, repeat=self.opts.repeat))

    def prepare_step(self) -> tuple[dict[str, Any], ModelRequest]:
        """The next model request and the first fields of its step record (prompt, what was sent, images)."""
        obs, planner = self.obs, self.planner
        assert obs is not None
        planner.set_action_space(self.env.action_space())
        request = planner.build_request(obs, seed=self.seed)
        self.planner_steps += 1
        head: dict[str, Any] = {
            "planner_step": self.planner_steps, "env_step_before": self.env_steps,
            "prompt": request.messages[-1].text,
            # what the model was actually sent with this turn (no image under language_only; views, frames)
            "sent_images": [p.name for p in request.messages[-1].content if isinstance(p, ImagePart)],
            # what the image the model saw shows (segmentation pixels, else objects with a box), for eb_core.errors
            "visible_objects": (obs.visible_objects if obs.visible_objects is not None else
                                [{"name": o.name, "type": o.type} for o in obs.objects if o.box is not None])}
        if self.planner_steps == 1 and obs.scene_objects is not None:
            head["scene_objects"] = obs.scene_objects  # what the scene holds, in view or not (eb_core.errors)
        if self.opts.save_images and self.opts.step_dir is not None and obs.primary_image is not None:
            self._save_images(head, obs)
        return head, request

    def _save_final_image(self) -> None:
        """The frame after the last action, so a viewer shows how the episode ended (the model never saw it)."""
        obs = self.obs
        if (not self.opts.save_images or self.opts.step_dir is None or obs is None or obs.primary_image is None
                or not self.env_steps):
            return
        (self.opts.step_dir / f"{FINAL_IMAGE_PREFIX}{obs.primary}.png").write_bytes(encode_png(obs.primary_image))

    def _save_images(self, head: dict[str, Any], obs: Observation) -> None:
        step_dir = self.opts.step_dir
        assert step_dir is not None and obs.primary_image is not None
        name = f"step{self.planner_steps:03d}_{obs.primary}.png"
        png = self.planner.last_primary_png or encode_png(obs.primary_image)
        (step_dir / name).write_bytes(png)
        head["image"] = name
        if self.cfg.multi_view:
            extra = []
            for key, img in obs.images.items():
                if key != obs.primary:
                    extra_name = f"step{self.planner_steps:03d}_{key}.png"
                    (step_dir / extra_name).write_bytes(encode_png(img))
                    extra.append(extra_name)
            head["extra_images"] = extra

    def handle_answer(self, head: dict[str, Any], response: ModelResponse) -> StepRecord:
        """Account the call, parse the answer and apply the rules: an output error, an empty plan, an invalid
        first item, or actions to execute. Returns the step's record."""
        call_usage = response.usage if response.usage.calls else response.usage.model_copy(update={"calls": 1})
        self.usage = self.usage + call_usage
        if self.opts.budget is not None:
            self.opts.budget.add(response.usage.cost_usd)
        planner = self.planner
        planner.record_answer(response.text)
        parsed = planner.parse(response.text)
        # built from plain values so every field it was given is written (the file keeps its shape)
        step = StepRecord.model_validate({
            **head, "raw_output": response.text, "usage": response.usage.model_dump(),
            "parsed": None if parsed.output is None else parsed.output.model_dump(), "error": parsed.error,
            "plan_error": parsed.plan_error, "actions": []})
        if parsed.error is not None:
            self.output_error(parsed.error)
        elif not parsed.actions and parsed.truncated_at is None:
            self.empty_plan = True
            if self.cfg.empty_plan_ends:
                self.end_reason = "empty_plan"
                self.done = True
            else:
                # navigation's original executed a random action: a step, not an invalid action
                self.output_error("the plan was empty but the task is not finished", count_invalid=False)
        elif not parsed.actions:  # the first plan item is not a valid action: nothing to execute
            self.invalid += 1
            if self.uses_step:  # the original executed something here too (navigation: "Done"; random actions)
                self.charged += 1
            planner.record_output_error(parsed.plan_error or "the first plan item was invalid")
        else:
            self.execute(step, parsed.actions)
            if parsed.plan_error and not self.done:
                planner.record_plan_cut(parsed.plan_error)
        return step

    def execute(self, step: StepRecord, actions: Sequence[Any]) -> None:
        """Run the plan in order, cut to the step budget; stop at the end, a failure (when re-planning), the
        invalid cap or the budget."""
        space = self.env.action_space()
        for action in actions[: max(0, self.budget_left())]:
            result = self.execute_one(step, space, action)
            if result.done:
                self.done = True
                self.end_reason = "success" if result.task_success else "done"
                break
            if not result.action_success and self.cfg.replan_on_failure:
                break
            if self.capped() or self.budget_left() <= 0:
                break

    def execute_one(self, step: StepRecord, space: Any, action: Any) -> StepResult:
        label = _expert_label(self.env, space) if self.opts.expert_labels else {}
        result = self.env.step(action)
        self.env_steps += 1
        self.obs = self.augment(result.observation)
        self.planner.observe(self.obs)
        self.progress = max(0.0, min(1.0, result.progress))
        self.success = result.task_success
        name = space.name_of(action)
        self.planner.record_action(self.env_steps, name, f"action {json.dumps(_jsonable(action))}",
                                   result.action_success, result.feedback)
        step.actions.append(ActionRecord.model_validate(
            {"env_step": self.env_steps, "action": _jsonable(action), "action_name": name,
             "success": result.action_success, "feedback": result.feedback, "progress": self.progress,
             "failure": result.info.get("failure"), **label,
             **{k: result.info[k] for k in _INFO_KEYS_RECORDED if k in result.info}}))
        if self.opts.hook is not None:
            self.opts.hook.eb_on_step_end(event=StepEndEvent(
                run_dir=self.opts.run_dir, task_id=self.task.id, env_step=self.env_steps,
                planner_step=self.planner_steps, action=_jsonable(action), action_name=name,
                action_success=result.action_success, feedback=result.feedback, progress=self.progress))
        if not result.action_success:
            self.invalid += 1
        return result

    def record(self, status: Literal["ok", "error"], error: str | None, wall_time_s: float) -> EpisodeRecord:
        ok = status == "ok"
        usage = self.usage
        return EpisodeRecord(
            task_id=self.task.id, subset=self.task.subset, instruction=self.task.instruction, seed=self.seed,
            repeat=self.opts.repeat,
            status=status,
            success=bool(self.success) if ok else False,
            progress=1.0 if self.success and ok else self.progress,
            end_reason=self.end_reason,
            env_steps=self.env_steps, planner_steps=self.planner_steps, invalid_actions=self.invalid,
            output_errors=self.output_errors, empty_plan=self.empty_plan,
            prompt_tokens=usage.prompt_tokens, completion_tokens=usage.completion_tokens, model_calls=usage.calls,
            cost_usd=usage.cost_usd, model_latency_s=usage.latency_s, wall_time_s=wall_time_s, error=error)


class EpisodeDriver:
    """One episode as a resumable state machine whose only blocking point is the model call.

    The caller asks for the next model request, makes the call however it likes (a thread pool, an async
    client, another machine) and hands the answer back; everything else (env reset, stepping, rendering,
    step files, hooks) happens inside :meth:`next_request` / :meth:`submit` / :meth:`fail`, on the caller's
    thread. So one thread can interleave many episodes, each with its own env, while their calls are in
    flight. The rules and the record are exactly those of :func:`run_episode`, which is a loop over it::

        driver = EpisodeDriver(env=env, task=task, seed=seed, planner=planner, backend=backend, env_config=cfg,
                               options=EpisodeOptions(step_dir=...))
        request = driver.next_request()
        while request is not None:
            driver.submit(backend.complete(request))   # or driver.fail(exc) when the call raised
            request = driver.next_request()
        record, steps = driver.record, driver.steps

    ``backend`` is still needed for :meth:`ModelBackend.start_episode` (offline baselines read the episode
    from it); the driver never calls ``backend.complete`` itself. :class:`ModelFatalError` and
    :class:`ModelBudgetExceeded` propagate out of :meth:`submit` / :meth:`fail`; every other failure of the
    call or of the env ends the episode with ``status="error"``. The option keywords (``step_dir=`` ...) are
    accepted in place of ``options`` for older callers.
    """

    def __init__(self, *, env: Env, task: Task, seed: int, planner: Planner, backend: ModelBackend,
                 env_config: EnvConfig, options: EpisodeOptions | None = None, **option_kwargs: Any) -> None:
        self._episode = _Episode(env, task, seed, planner, backend, env_config, _options(options, option_kwargs))
        self._flow = self._episode.flow()
        self._started = False
        self._request: ModelRequest | None = None
        self.record: EpisodeRecord | None = None
        """The episode's record once it has ended (``next_request()`` returned None)."""

    @property
    def steps(self) -> list[StepRecord]:
        """The step records so far, as written to ``steps.jsonl`` (kept in memory: nothing re-reads the file)."""
        return self._episode.steps

    @property
    def done(self) -> bool:
        return self.record is not None

    @property
    def waiting(self) -> bool:
        """A request was handed out and its answer is due."""
        return self._request is not None

    def next_request(self) -> ModelRequest | None:
        """The pending model request (running the episode up to it on first use); None when it has ended."""
        if self.record is not None:
            return None
        if not self._started:
            self._started = True
            self._advance(lambda: next(self._flow))
        return self._request

    def submit(self, response: ModelResponse) -> None:
        """Hand back the answer to the pending request; runs the episode up to its next request or its end."""
        self._check_waiting()
        self._advance(lambda: self._flow.send(response))

    def fail(self, exc: BaseException) -> None:
        """The pending call raised ``exc``: the episode handles it as :func:`run_episode` would."""
        self._check_waiting()
        self._advance(lambda: self._flow.throw(exc))

    def close(self) -> None:
        """Abandon the episode (closes its step file); no record is produced."""
        self._flow.close()
        self._request = None

    def _check_waiting(self) -> None:
        if self._request is None:
            raise RuntimeError("no model request is pending: call next_request() first (or the episode has ended)")

    def _advance(self, step: Callable[[], ModelRequest]) -> None:
        self._request = None
        try:
            self._request = step()
        except StopIteration as stop:
            self.record = stop.value


def play(driver: EpisodeDriver, backend: ModelBackend) -> EpisodeRecord:
    """Drive ``driver`` to its end with blocking ``backend.complete`` calls; return its record."""
    request = driver.next_request()
    while request is not None:
        try:
            response = backend.complete(request)
        except Exception as exc:
            driver.fail(exc)
        else:
            driver.submit(response)
        request = driver.next_request()
    assert driver.record is not None
    return driver.record


def run_episode(*, env: Env, task: Task, seed: int, planner: Planner, backend: ModelBackend, env_config: EnvConfig,
                options: EpisodeOptions | None = None, **option_kwargs: Any) -> EpisodeRecord:
    """Play ``task`` to the end and return its record. Model transient errors and env exceptions give
    ``status="error"``; :class:`ModelFatalError` and :class:`ModelBudgetExceeded` propagate. Options as for
    :class:`EpisodeDriver`."""
    driver = EpisodeDriver(env=env, task=task, seed=seed, planner=planner, backend=backend, env_config=env_config,
                           options=options, **option_kwargs)
    return play(driver, backend)
