"""Evaluation during training: play a policy callable on the benchmark's protocol and get ``eb run``'s summary.

    from eb_core.evaluate import evaluate
    summary = evaluate(my_policy, env="navigation", split="val", limit=50)
    summary["overall"]["success_rate"], summary["overall"]["success_rate_ci"]

The policy is called once per planner call, exactly where ``eb run`` calls a model: it gets what the model would
get and returns the answer text (the JSON plan). Two forms:

* ``policy(observation) -> str`` (the default, ``policy_input="observation"``): ``observation`` is the Gymnasium
  prompt-mode observation, ``{"prompt": str, "images": tuple[np.ndarray, ...]}``, as :class:`eb_core.gym.EBEnv`
  and ``eb serve`` give it;
* ``policy(prompt) -> str`` (``policy_input="text"``): the prompt text only.

A policy that takes a second argument also gets ``info``: ``task_id``, ``subset``, ``instruction``, ``seed``,
``call`` (0, 1, ... within the episode) and, with ``expert=True``, ``expert_plan`` (the world's expert's plan from
the current state, as action ids) — for behaviour-cloning baselines and for checking a policy wrapper.

It runs the real runner (``eb_core.runner.run``) with a built-in model backend, ``policy``, that calls the
callable, so the scores, intervals and the run directory (when ``run_dir`` is given) are those of ``eb run``.
"""

from __future__ import annotations

import inspect
import shutil
import tempfile
import time
import uuid
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from eb_core.model import EpisodeContext, ModelBackend, ModelRequest, ModelResponse, Usage

__all__ = ["PolicyBackend", "evaluate"]

_POLICIES: dict[str, tuple[Callable[..., str], str, bool]] = {}
"""Policies of the evaluations running in this process, by id (the run's config carries only the id)."""


def _takes_info(policy: Callable[..., Any]) -> bool:
    try:
        params = [p for p in inspect.signature(policy).parameters.values()
                  if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD, p.VAR_POSITIONAL)]
    except (TypeError, ValueError):
        return False
    return len(params) >= 2 or any(p.kind == p.VAR_POSITIONAL for p in params)


class PolicyBackend(ModelBackend):
    """The model backend behind :func:`evaluate`: each planner call goes to the policy callable."""

    supports_images = True
    supports_json_schema = False

    def __init__(self, policy_id: str, **_: Any) -> None:
        if policy_id not in _POLICIES:
            raise ValueError("the policy backend plays a callable given to eb_core.evaluate.evaluate(); it cannot be "
                             "selected with model= on the command line")
        self.policy, self.policy_input, self.expert = _POLICIES[policy_id]
        self.with_info = _takes_info(self.policy)
        self.ctx: EpisodeContext | None = None
        self.calls = 0

    def start_episode(self, ctx: EpisodeContext) -> None:
        self.ctx, self.calls = ctx, 0

    def complete(self, request: ModelRequest) -> ModelResponse:
        from eb_core.gym.env import request_observation

        t0 = time.perf_counter()
        prompt, images = request_observation(request)
        arg: Any = prompt if self.policy_input == "text" else {"prompt": prompt, "images": tuple(images)}
        if self.with_info:
            assert self.ctx is not None
            info: dict[str, Any] = {"task_id": self.ctx.task.id, "subset": self.ctx.task.subset,
                                    "instruction": self.ctx.task.instruction, "seed": self.ctx.seed,
                                    "call": self.calls}
            if self.expert:
                info["expert_plan"] = self.ctx.env.expert_plan()
            answer = self.policy(arg, info)
        else:
            answer = self.policy(arg)
        self.calls += 1
        if not isinstance(answer, str):
            raise TypeError(f"the policy must return the answer text (a str), got {type(answer).__name__}")
        return ModelResponse(text=answer, model="policy",
                             usage=Usage(calls=1, latency_s=time.perf_counter() - t0))


def evaluate(policy: Callable[..., str], env: str, *, taskset: str = "classic", subset: str | Sequence[str] | None = None,
             limit: int | None = None, split: str = "test", seed: int = 0, repeats: int = 1,
             overrides: Sequence[str] = (), policy_input: str = "observation", expert: bool = False,
             run_dir: str | Path | None = None, quiet: bool = True) -> dict[str, Any]:
    """Play ``policy`` on ``env``'s tasks with the benchmark's protocol and return ``eb run``'s summary.

    Args:
        policy: the callable (see the module docstring).
        env: the world (``navigation``, ``alfred``, ``habitat``, ``manipulation`` or a plugin's).
        taskset: ``classic`` or a set the world lists (``hard``).
        subset, limit, split, seed, repeats: as ``eb run``'s ``subset=``, ``limit=``, ``split=``, ``seed=`` and
            ``runner.repeats=`` (``split=val limit=N`` during training).
        overrides: further Hydra overrides (``ablation=no_feedback``, ``env.resolution=300``...).
        policy_input: ``observation`` or ``text``.
        expert: give the policy ``info["expert_plan"]`` (needs a two-argument policy).
        run_dir: keep the run directory there (a fresh folder; ``eb report``/``eb show`` read it); default: none.
        quiet: no progress output.
    """
    from eb_core.gym.env import _compose, _registry
    from eb_core.runner import run

    if policy_input not in ("observation", "text"):
        raise ValueError(f"policy_input must be 'observation' or 'text', got {policy_input!r}")
    if not callable(policy):
        raise TypeError(f"policy must be a callable returning the answer text, got {type(policy).__name__}")
    extra = [f"split={split}", f"seed={seed}", f"runner.repeats={repeats}", "runner.workers=1",
             f"runner.quiet={str(quiet).lower()}"]
    if taskset != "classic":
        extra.append(f"taskset={taskset}")
    if limit is not None:
        extra.append(f"limit={limit}")
    if subset is not None:
        extra.append(f"subset={subset}" if isinstance(subset, str) else f"subset=[{','.join(subset)}]")
    cfg = _compose(env, tuple([*extra, *overrides]))
    policy_id = uuid.uuid4().hex
    cfg = cfg.model_copy(update={"model": type(cfg.model)(name="policy", backend="policy", policy_id=policy_id)})
    _POLICIES[policy_id] = (policy, policy_input, expert)
    tmp = None
    if run_dir is None:
        tmp = tempfile.mkdtemp(prefix="eb-evaluate-")
        target = Path(tmp) / "run"
    else:
        target = Path(run_dir)
    try:
        return run(cfg, target, registry=_registry())
    finally:
        _POLICIES.pop(policy_id, None)
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
