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
from pathlib import Path
from typing import Any

from eb_core.config import EnvConfig
from eb_core.env import Env, Observation, Task
from eb_core.events import EpisodeStartEvent, StepEndEvent
from eb_core.model import (EpisodeContext, ImagePart, ModelBackend, ModelBudgetExceeded, ModelFatalError,
                           ModelRequest, ModelResponse, Usage)
from eb_core.planner import VLMPlanner, encode_png
from eb_core.records import EpisodeRecord

__all__ = ["BudgetGuard", "EpisodeDriver", "run_episode"]


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
_INFO_KEYS_RECORDED = ("distance_to_goal", "wrong_target")


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


def _episode_flow(
    *,
    env: Env,
    task: Task,
    seed: int,
    planner: VLMPlanner,
    backend: ModelBackend,
    env_config: EnvConfig,
    step_dir: Path | None = None,
    save_images: bool = True,
    augmenters: Sequence[Callable[[Observation], Observation]] = (),
    budget: BudgetGuard | None = None,
    hook: Any = None,
    run_dir: str = "",
    expert_labels: bool = False,
    repeat: int = 0,
) -> Generator[ModelRequest, ModelResponse, EpisodeRecord]:
    """The episode as a generator: yields each model request, receives its response (or the call's
    exception, thrown in) and returns the record. Driven by :class:`EpisodeDriver`."""
    started = time.perf_counter()
    usage = Usage()
    rec: dict[str, Any] = dict(task_id=task.id, subset=task.subset, instruction=task.instruction, seed=seed,
                               repeat=repeat)
    env_steps = planner_steps = invalid = output_errors = 0
    progress, success, empty_plan = 0.0, False, False
    end_reason = "max_steps"
    steps_file = None
    if step_dir is not None:
        step_dir.mkdir(parents=True, exist_ok=True)
        steps_file = open(step_dir / "steps.jsonl", "w", encoding="utf-8")
    if hook is not None:
        hook.eb_on_episode_start(event=EpisodeStartEvent(
            run_dir=run_dir, task_id=task.id, subset=task.subset, instruction=task.instruction, seed=seed))

    uses_step = env_config.output_error_uses_step
    # Output errors that use no step are bounded by the invalid cap, or by max_steps of them without one.
    invalid_cap = env_config.max_invalid_actions
    if invalid_cap is None and not uses_step:
        invalid_cap = env_config.max_steps

    charged = 0  # answers that executed nothing but use a step of the budget (where uses_step)

    def budget_left() -> int:
        return env_config.max_steps - env_steps - charged

    def augment(o: Observation) -> Observation:
        for aug in augmenters:
            o = aug(o)
        return o

    def output_error(reason: str, count_invalid: bool = True) -> None:
        nonlocal output_errors, invalid, charged
        output_errors += 1
        if count_invalid or not uses_step:
            invalid += 1
        if uses_step:
            charged += 1
        planner.record_output_error(reason)

    try:
        obs = augment(env.reset(task, seed))
        space = env.action_space()
        planner.reset(task, env.prompt_parts(), space)
        planner.observe(obs)
        backend.start_episode(EpisodeContext(env=env, task=task, seed=seed, run_dir=run_dir or None,
                                             repeat=repeat))
        done = False
        while not done and budget_left() > 0:
            if invalid_cap is not None and invalid >= invalid_cap:
                end_reason = "invalid_cap"
                break
            planner.set_action_space(env.action_space())
            request = planner.build_request(obs, seed=seed)
            planner_steps += 1
            step_rec: dict[str, Any] = {"planner_step": planner_steps, "env_step_before": env_steps,
                                        "prompt": request.messages[-1].text}
            # what the model was actually sent with this turn (no image under language_only; views, frames)
            step_rec["sent_images"] = [p.name for p in request.messages[-1].content if isinstance(p, ImagePart)]
            # what the image the model saw shows (objects with a box), for the perception check (eb_core.errors)
            step_rec["visible_objects"] = [{"name": o.name, "type": o.type} for o in obs.objects if o.box is not None]
            if save_images and step_dir is not None and obs.primary_image is not None:
                name = f"step{planner_steps:03d}_{obs.primary}.png"
                png = getattr(planner, "last_primary_png", None) or encode_png(obs.primary_image)
                (step_dir / name).write_bytes(png)
                step_rec["image"] = name
                if env_config.multi_view:
                    extra = []
                    for key, img in obs.images.items():
                        if key != obs.primary:
                            extra_name = f"step{planner_steps:03d}_{key}.png"
                            (step_dir / extra_name).write_bytes(encode_png(img))
                            extra.append(extra_name)
                    step_rec["extra_images"] = extra
            response = yield request  # the only blocking point: the model call, made by the caller
            call_usage = response.usage if response.usage.calls else response.usage.model_copy(update={"calls": 1})
            usage = usage + call_usage
            if budget is not None:
                budget.add(response.usage.cost_usd)
            step_rec["raw_output"] = response.text
            step_rec["usage"] = response.usage.model_dump()
            planner.record_answer(response.text)
            parsed = planner.parse(response.text)
            step_rec["parsed"] = None if parsed.output is None else parsed.output.model_dump()
            step_rec["error"] = parsed.error
            step_rec["plan_error"] = parsed.plan_error
            actions_log: list[dict[str, Any]] = []
            step_rec["actions"] = actions_log

            if parsed.error is not None:
                output_error(parsed.error)
            elif not parsed.actions and parsed.truncated_at is None:
                empty_plan = True
                if env_config.empty_plan_ends:
                    end_reason = "empty_plan"
                    done = True
                else:
                    # navigation's original executed a random action: a step, not an invalid action
                    output_error("the plan was empty but the task is not finished", count_invalid=False)
            elif not parsed.actions:  # the first plan item is not a valid action: nothing to execute
                invalid += 1
                if uses_step:  # the original executed something here too (navigation: "Done"; random actions)
                    charged += 1
                planner.record_output_error(parsed.plan_error or "the first plan item was invalid")
            else:
                space = env.action_space()
                for action in parsed.actions[: max(0, budget_left())]:
                    label: dict[str, Any] = {}
                    if expert_labels:
                        label = _expert_label(env, space)
                    result = env.step(action)
                    env_steps += 1
                    obs = augment(result.observation)
                    planner.observe(obs)
                    progress = max(0.0, min(1.0, result.progress))
                    success = result.task_success
                    name = space.name_of(action)
                    planner.record_action(env_steps, name, f"action {json.dumps(_jsonable(action))}",
                                          result.action_success, result.feedback)
                    actions_log.append({"env_step": env_steps, "action": _jsonable(action), "action_name": name,
                                        "success": result.action_success, "feedback": result.feedback,
                                        "progress": progress, "failure": result.info.get("failure"), **label,
                                        **{k: result.info[k] for k in _INFO_KEYS_RECORDED if k in result.info}})
                    if hook is not None:
                        hook.eb_on_step_end(event=StepEndEvent(
                            run_dir=run_dir, task_id=task.id, env_step=env_steps, planner_step=planner_steps,
                            action=_jsonable(action), action_name=name, action_success=result.action_success,
                            feedback=result.feedback, progress=progress))
                    if not result.action_success:
                        invalid += 1
                    if result.done:
                        done = True
                        end_reason = "success" if result.task_success else "done"
                        break
                    if not result.action_success and env_config.replan_on_failure:
                        break
                    if invalid_cap is not None and invalid >= invalid_cap:
                        break
                    if budget_left() <= 0:
                        break
                if parsed.plan_error and not done:
                    planner.record_plan_cut(parsed.plan_error)
            if steps_file is not None:
                steps_file.write(json.dumps(step_rec, default=str) + "\n")
                steps_file.flush()
        if not done and end_reason == "max_steps" and invalid_cap is not None and invalid >= invalid_cap:
            end_reason = "invalid_cap"
        status = "ok"
        error = None
    except (ModelFatalError, ModelBudgetExceeded):
        raise
    except Exception as exc:  # a model that stayed unreachable, or an env bug: recorded, the run goes on
        status = "error"
        end_reason = "error"
        error = f"{type(exc).__name__}: {exc}\n{traceback.format_exc(limit=20)}"
    finally:
        if steps_file is not None:
            steps_file.close()
    return EpisodeRecord(
        **rec,
        status=status,  # type: ignore[arg-type]
        success=bool(success) if status == "ok" else False,
        progress=1.0 if success and status == "ok" else progress,
        end_reason=end_reason,  # type: ignore[arg-type]
        env_steps=env_steps,
        planner_steps=planner_steps,
        invalid_actions=invalid,
        output_errors=output_errors,
        empty_plan=empty_plan,
        prompt_tokens=usage.prompt_tokens,
        completion_tokens=usage.completion_tokens,
        model_calls=usage.calls,
        cost_usd=usage.cost_usd,
        model_latency_s=usage.latency_s,
        wall_time_s=time.perf_counter() - started,
        error=error,
    )


class EpisodeDriver:
    """One episode as a resumable state machine whose only blocking point is the model call.

    The caller asks for the next model request, makes the call however it likes (a thread pool, an async
    client, another machine) and hands the answer back; everything else (env reset, stepping, rendering,
    step files, hooks) happens inside :meth:`next_request` / :meth:`submit` / :meth:`fail`, on the caller's
    thread. So one thread can interleave many episodes, each with its own env, while their calls are in
    flight. The rules and the record are exactly those of :func:`run_episode`, which is a loop over it::

        driver = EpisodeDriver(env=env, task=task, seed=seed, planner=planner, backend=backend, env_config=cfg)
        request = driver.next_request()
        while request is not None:
            driver.submit(backend.complete(request))   # or driver.fail(exc) when the call raised
            request = driver.next_request()
        record = driver.record

    ``backend`` is still needed for :meth:`ModelBackend.start_episode` (offline baselines read the episode
    from it); the driver never calls ``backend.complete`` itself. :class:`ModelFatalError` and
    :class:`ModelBudgetExceeded` propagate out of :meth:`submit` / :meth:`fail`; every other failure of the
    call or of the env ends the episode with ``status="error"``. Keyword arguments are those of
    :func:`run_episode`.
    """

    def __init__(self, **kwargs: Any) -> None:
        self._flow = _episode_flow(**kwargs)
        self._started = False
        self._request: ModelRequest | None = None
        self.record: EpisodeRecord | None = None
        """The episode's record once it has ended (``next_request()`` returned None)."""

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


def run_episode(
    *,
    env: Env,
    task: Task,
    seed: int,
    planner: VLMPlanner,
    backend: ModelBackend,
    env_config: EnvConfig,
    step_dir: Path | None = None,
    save_images: bool = True,
    augmenters: Sequence[Callable[[Observation], Observation]] = (),
    budget: BudgetGuard | None = None,
    hook: Any = None,
    run_dir: str = "",
    expert_labels: bool = False,
    repeat: int = 0,
) -> EpisodeRecord:
    """Play ``task`` to the end and return its record. Model transient errors and env exceptions give
    ``status="error"``; :class:`ModelFatalError` and :class:`ModelBudgetExceeded` propagate."""
    driver = EpisodeDriver(env=env, task=task, seed=seed, planner=planner, backend=backend, env_config=env_config,
                           step_dir=step_dir, save_images=save_images, augmenters=augmenters, budget=budget,
                           hook=hook, run_dir=run_dir, expert_labels=expert_labels, repeat=repeat)
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
