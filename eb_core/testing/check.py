"""``check_env``: one function that exercises an environment the way the runner will."""

from __future__ import annotations

from typing import Any

import numpy as np

from eb_core.env import DiscreteActionSpace, Env, Observation, PromptParts, StepResult, Task, VectorActionSpace


class EnvCheckError(AssertionError):
    """An environment breaks the contract; the message says which rule."""


def _check_observation(obs: Any, where: str) -> None:
    if not isinstance(obs, Observation):
        raise EnvCheckError(f"{where} must return an Observation, got {type(obs).__name__}")
    if obs.primary is not None and obs.primary not in obs.images:
        raise EnvCheckError(f"{where}: primary image {obs.primary!r} is not among images {sorted(obs.images)}")
    if obs.primary is None and obs.text is None:
        raise EnvCheckError(f"{where}: an observation needs a primary image or a text description")
    for obj in obs.objects:
        if obj.box is not None:
            x0, y0, x1, y1 = obj.box
            if not (x0 <= x1 and y0 <= y1):
                raise EnvCheckError(f"{where}: box of {obj.name!r} is not (x0, y0, x1, y1): {obj.box}")


def check_env(env: Env, task: Task, seed: int = 0, max_steps: int = 5) -> dict[str, Any]:
    """Reset ``env`` on ``task`` and take up to ``max_steps`` actions, checking every contract rule.

    Uses the env's expert plan when it has one (else the first action). Returns a small report.
    Raises :class:`EnvCheckError` naming the broken rule.
    """
    obs = env.reset(task, seed)
    _check_observation(obs, "reset()")
    first_image = None if obs.primary_image is None else np.array(obs.primary_image, copy=True)
    space = env.action_space()
    if not isinstance(space, (DiscreteActionSpace, VectorActionSpace)):
        raise EnvCheckError(f"action_space() must return an ActionSpace, got {type(space).__name__}")
    if isinstance(space, DiscreteActionSpace) and len(space) == 0:
        raise EnvCheckError("action_space() has no actions")
    parts = env.prompt_parts()
    if not isinstance(parts, PromptParts) or not parts.role.strip():
        raise EnvCheckError("prompt_parts() must return PromptParts with a non-empty role")
    plan = env.expert_plan()
    if plan is None:
        plan = [0] if isinstance(space, DiscreteActionSpace) else [space.plan_item_example()["action"]]
    steps = 0
    last: StepResult | None = None
    for action in plan[:max_steps]:
        result = env.step(action)
        steps += 1
        if not isinstance(result, StepResult):
            raise EnvCheckError(f"step() must return a StepResult, got {type(result).__name__}")
        _check_observation(result.observation, f"step({action!r})")
        if not isinstance(result.feedback, str):
            raise EnvCheckError("step() feedback must be text")
        if result.task_success and result.progress < 1.0:
            raise EnvCheckError("a successful task must report progress 1.0")
        last = result
        if result.done:
            break
    # Determinism: the same task and seed give the same first image.
    obs2 = env.reset(task, seed)
    if first_image is not None:
        again = obs2.primary_image
        if again is None or again.shape != first_image.shape or not np.array_equal(again, first_image):
            raise EnvCheckError("reset() with the same task and seed must give the same primary image")
    return {"steps": steps, "last_feedback": None if last is None else last.feedback,
            "n_actions": len(space) if isinstance(space, DiscreteActionSpace) else None}
