"""N EmbodiedBench environments stepped together on W worker processes (or W Ray actors).

:func:`make_vector_env` builds an :class:`EBVectorEnv`, a Gymnasium ``VectorEnv``: the N environments are split
into W groups (``workers``, by default the config's ``runner.workers``), each group living in one worker process
that holds its N/W environments and steps them in turn on its one thread -- the layout of the runner's in-flight
workers (issue 13): one interpreter, one set of imported modules and shared renderer resources for many
environments, so memory per environment falls as N grows. ``executor="ray"`` puts each group in a Ray actor
instead (the runner's ``runner.executor=ray``), so a trainer on a GPU node steps environments on CPU nodes.

Observations come back batched (Gymnasium's ``concatenate``: a tuple of prompts and a tuple of image tuples in
prompt mode, a stacked image array and a tuple of texts in raw mode); ``info`` entries are arrays with a
``_key`` mask. Autoreset is Gymnasium's ``NextStep`` (default), ``SameStep`` or ``Disabled``.

Nothing an environment does takes the trainer down:

* an environment that raises (in ``step`` or in the autoreset that follows) returns ``truncated=True`` with
  ``info["error"]``; it is rebuilt in its worker and reset on the next step;
* a worker process that dies (killed, out of memory, a segfault in a renderer) or stops answering for
  ``step_timeout_s`` loses only its environments' current episodes: they return ``truncated=True`` with
  ``info["error"]``, the process is started again with fresh environments, and they reset on the next step.
  A lost Ray actor is replaced the same way.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable, Sequence
from typing import Any

import gymnasium
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space, concatenate, create_empty_array

from eb_core.gym._workers import _RAY_ENV_VARS, EnvGroup, _ProcessWorker, _RayWorker, _WorkerLost

__all__ = ["EBVectorEnv", "EnvGroup", "make_vector_env"]

_START_ATTEMPTS = 3


def _resolve(world: str) -> str:
    """Accept ``EB/Navigation-v0``, ``eb_core.gym:EB/Navigation-v0`` or the env name ``navigation``."""
    from eb_core.gym.ids import gym_id, registered_ids

    if ":" in world:
        world = world.split(":", 1)[1]
    if world in registered_ids():
        return world
    gid = gym_id(world)
    if gid in registered_ids():
        return gid
    raise ValueError(f"unknown world {world!r}; registered: {', '.join(registered_ids())} "
                     f"(is its plugin installed? `eb list` shows the worlds)")



def reset_seeds(seed: int | Sequence[int | None] | None, n: int) -> list[int | None]:
    """The per-environment seeds of a vector ``reset(seed=...)``, as gymnasium's vector envs read them: ``None``
    for all, an int ``s`` for ``s, s+1, ...``, or one seed (or ``None``) per environment."""
    if seed is None:
        return [None] * n
    if isinstance(seed, (int, np.integer)):
        return [int(seed) + i for i in range(n)]
    seeds = [None if s is None else int(s) for s in seed]
    if len(seeds) != n:
        raise ValueError(f"reset(seed=...) needs {n} seeds (one per environment), got {len(seeds)}")
    return seeds

class _MakeEnv:
    """A picklable environment factory: ``gymnasium.make(gym_id, **kwargs)`` in the worker, after registering
    the worlds the worker's plugins provide."""

    def __init__(self, gid: str, world: str, kwargs: dict[str, Any]) -> None:
        self.gid, self.world, self.kwargs = gid, world, kwargs

    def __call__(self) -> gymnasium.Env:
        from eb_core.gym.ids import register_worlds

        if self.gid not in gymnasium.registry:
            register_worlds()
        if self.gid not in gymnasium.registry:  # a world from a plugin the worker cannot see under that id
            gymnasium.register(self.gid, entry_point="eb_core.gym.env:EBEnv", kwargs={"world": self.world},
                               disable_env_checker=True)
        return gymnasium.make(self.gid, **self.kwargs)


class EBVectorEnv(VectorEnv):
    """``len(env_fns)`` environments in ``workers`` groups, each group in one worker process or Ray actor.

    Args:
        env_fns: one picklable factory per environment (pickled with cloudpickle, so closures work).
        workers: worker processes (or actors); each holds ``len(env_fns) / workers`` environments.
        executor: ``local`` (worker processes on this machine) or ``ray`` (Ray actors, ``num_cpus=1`` each
            unless ``ray_options`` says otherwise; joins ``ray_address``, ``$RAY_ADDRESS`` or a local Ray).
        context: multiprocessing start method of local workers. ``forkserver`` (default) forks them from a
            clean server process, never from a process holding an OpenGL context (a forked EGL context hangs).
        autoreset_mode: ``NextStep`` (default), ``SameStep`` or ``Disabled`` (Gymnasium's modes).
        step_timeout_s: a worker that has not answered a step or reset this long is killed and replaced
            (its environments' episodes end truncated with an error); ``None`` waits for ever.
    """

    def __init__(self, env_fns: Sequence[Callable[[], gymnasium.Env]], *, workers: int = 1,
                 executor: str = "local", context: str | None = "forkserver",
                 autoreset_mode: str | AutoresetMode = AutoresetMode.NEXT_STEP,
                 step_timeout_s: float | None = None, start_timeout_s: float | None = 600.0,
                 ray_options: dict[str, Any] | None = None, ray_address: str | None = None) -> None:
        import pickle

        import cloudpickle

        _refuse_in_bootstrapping_worker()

        self.workers: list[Any] = []  # one handle per worker (a process or a Ray actor); None while being replaced
        self.closed, self._ray_started = False, False
        n = len(env_fns)
        if n < 1:
            raise ValueError("num_envs must be >= 1, got 0")
        if not isinstance(workers, int) or workers < 1:
            raise ValueError(f"workers must be an integer >= 1, got {workers!r} (runner.workers=N sets it too)")
        if executor not in ("local", "ray"):
            raise ValueError(f"executor must be 'local' or 'ray', got {executor!r}")
        self.num_envs = n
        self.executor, self.context = executor, context
        self.autoreset_mode = autoreset_mode if isinstance(autoreset_mode, AutoresetMode) \
            else AutoresetMode(autoreset_mode)
        self.step_timeout_s, self.start_timeout_s = step_timeout_s, start_timeout_s
        w = min(workers, n)
        bounds = np.linspace(0, n, w + 1).round().astype(int)
        self.slices = [range(int(bounds[k]), int(bounds[k + 1])) for k in range(w)]
        if executor == "ray":
            self._ray_started = self._connect_ray(ray_address)  # before anything that can fail after it
            self.ray_options = {"num_cpus": 1, "max_restarts": 0, **(ray_options or {})}
            environ = {k: v for k, v in os.environ.items() if k.startswith(_RAY_ENV_VARS)}
        else:
            self.ray_options = {}
            environ = dict(os.environ)
            if context == "forkserver":
                import multiprocessing

                multiprocessing.get_context("forkserver").set_forkserver_preload(["eb_core.gym"])
        self.payloads = [pickle.dumps((cloudpickle.dumps([env_fns[i] for i in s]), environ, list(sys.path)))
                         for s in self.slices]
        self.workers = [None] * w
        self.restarts = 0
        try:
            for k in range(w):  # all workers build their environments at once
                self.workers[k] = self._launch(k)
            for k in range(w):
                try:
                    self.workers[k].wait_ready()
                except _WorkerLost:
                    self.workers[k] = self._start(k)
        except BaseException:
            self.close()
            raise
        info = self.workers[0].info
        self.single_observation_space = info["observation_space"]
        self.single_action_space = info["action_space"]
        self.observation_space = batch_space(self.single_observation_space, n)
        self.action_space = batch_space(self.single_action_space, n)
        self.metadata = {**info["metadata"], "autoreset_mode": self.autoreset_mode}
        self.render_mode = info["render_mode"]
        self.spec = info["spec"]
        self._last_obs: list[Any] = [None] * n
        self._needs_reset = np.ones(n, dtype=bool)  # NextStep: reset on the next step

    # -- workers -----------------------------------------------------------------------------------

    @staticmethod
    def _connect_ray(address: str | None) -> bool:
        try:
            import ray
        except ImportError:
            raise RuntimeError('executor="ray" needs Ray, which is not installed: pip install "embodiedbench[ray]" '
                               '(or use executor="local")') from None
        if ray.is_initialized():
            return False
        address = address or os.environ.get("RAY_ADDRESS") or None
        ray.init(address=address, include_dashboard=False, log_to_driver=False, configure_logging=False)
        return True

    def _launch(self, k: int) -> Any:
        if self.executor == "ray":
            return _RayWorker(self.payloads[k], self.ray_options, self.start_timeout_s)
        return _ProcessWorker(self.payloads[k], self.context, self.start_timeout_s)

    def _start(self, k: int) -> Any:
        last: Exception | None = None
        for _ in range(_START_ATTEMPTS):
            try:
                worker = self._launch(k)
                worker.wait_ready()
                return worker
            except _WorkerLost as exc:
                last = exc
        hint = ""
        if "exited while starting" in str(last) and self.context in ("spawn", "forkserver"):
            hint = (f"; if the script that builds the vector env does so at its top level, put that code under "
                    f"`if __name__ == \"__main__\":` ({self.context} workers import the script again)")
        raise RuntimeError(f"worker {k} could not be started ({_START_ATTEMPTS} attempts): {last}{hint}") from None

    @property
    def worker_pids(self) -> list[int]:
        """Process id of each worker (the actor's process under Ray), in group order."""
        return [w.pid for w in self.workers]

    def worker_of(self, env_index: int) -> int:
        """Which worker holds environment ``env_index``."""
        for k, s in enumerate(self.slices):
            if env_index in s:
                return k
        raise IndexError(f"env_index must be in [0, {self.num_envs}), got {env_index}")

    def _exchange(self, ops: list[Any]) -> tuple[list[Any], dict[int, str]]:
        """Send each worker its environments' operations, gather the results. A worker that dies or stops
        answering is replaced; its environments' results are ``("lost", why)``."""
        if self.closed:
            raise RuntimeError("the vector env is closed")
        busy = [k for k, s in enumerate(self.slices) if any(ops[i] is not None for i in s)]
        for k in busy:
            self.workers[k].send([ops[i] for i in self.slices[k]])
        results: list[Any] = [None] * self.num_envs
        lost: dict[int, str] = {}
        deadline = None if self.step_timeout_s is None else time.monotonic() + self.step_timeout_s
        for k in busy:
            timeout = None if deadline is None else max(0.0, deadline - time.monotonic())
            try:
                out = self.workers[k].recv(timeout)
            except _WorkerLost as exc:
                lost[k] = str(exc)
                continue
            for i, r in zip(self.slices[k], out):
                results[i] = r
        for k, why in lost.items():
            self.workers[k].kill()
            self.restarts += 1
            self.workers[k] = self._start(k)
            for i in self.slices[k]:
                self._needs_reset[i] = True
                if ops[i] is not None:
                    results[i] = ("lost", f"{why}; its environments were rebuilt in a new worker")
        return results, lost

    # -- gymnasium API -----------------------------------------------------------------------------

    def reset(self, *, seed: int | Sequence[int | None] | None = None,
              options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        n = self.num_envs
        seeds = reset_seeds(seed, n)
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        if mask is None:
            mask = np.ones(n, dtype=bool)
        elif not (isinstance(mask, np.ndarray) and mask.dtype == np.bool_ and mask.shape == (n,)):
            raise ValueError(f"options['reset_mask'] must be a numpy bool array of shape ({n},)")
        opts = options or None
        ops: list[Any] = [("reset", seeds[i], opts) if mask[i] else None for i in range(n)]
        results, _ = self._exchange(ops)
        retry = [i for i in range(n) if results[i] is not None and results[i][0] == "lost"]
        if retry:  # a worker died during the reset: its replacement resets them
            again, _ = self._exchange([ops[i] if i in retry else None for i in range(n)])
            for i in retry:
                results[i] = again[i]
        infos: dict[str, Any] = {}
        for i in range(n):
            r = results[i]
            if r is None:
                if self._last_obs[i] is None:
                    raise RuntimeError(f"environment {i} has never been reset; include it in reset_mask")
                continue
            if r[0] != "reset":
                raise RuntimeError(f"environment {i} could not be reset: {r[1]}")
            self._last_obs[i] = r[1]
            self._needs_reset[i] = False
            infos = self._add_info(infos, r[2], i)
        return self._batch(), infos

    def step(self, actions: Any) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        n = self.num_envs
        acts = list(actions)  # a tuple of answer texts, an (N,) array of ids or an (N, 7) array of vectors
        if len(acts) != n:
            raise ValueError(f"step() needs {n} actions (one per environment), got {len(acts)}")
        next_step = self.autoreset_mode == AutoresetMode.NEXT_STEP
        same_step = self.autoreset_mode == AutoresetMode.SAME_STEP
        ops: list[Any] = []
        for i in range(n):
            if self._needs_reset[i] and self.autoreset_mode != AutoresetMode.DISABLED:
                ops.append(("reset", None, None))
            else:
                ops.append(("step", acts[i], same_step))
        results, _ = self._exchange(ops)
        rewards = np.zeros(n, dtype=np.float64)
        terminated = np.zeros(n, dtype=np.bool_)
        truncated = np.zeros(n, dtype=np.bool_)
        infos: dict[str, Any] = {}
        for i, r in enumerate(results):
            kind = r[0]
            if kind == "reset":
                self._last_obs[i] = r[1]
                self._needs_reset[i] = False
                info = r[2]
            elif kind == "step":
                self._last_obs[i] = r[1]
                rewards[i], terminated[i], truncated[i], info = r[2], r[3], r[4], r[5]
                done = bool(r[3] or r[4])
                self._needs_reset[i] = (done and next_step) or bool(r[6])
            else:  # "error" (the env raised) or "lost" (its worker died): the episode ends, truncated
                truncated[i] = True
                self._needs_reset[i] = True
                info = {"error": r[1]}
            infos = self._add_info(infos, info, i)
        return self._batch(), rewards, terminated, truncated, infos

    def _batch(self) -> Any:
        obs = [o if o is not None else self.single_observation_space.sample() for o in self._last_obs]
        out: Any = create_empty_array(self.single_observation_space, self.num_envs)
        return concatenate(self.single_observation_space, obs, out)

    def call(self, name: str, *args: Any, **kwargs: Any) -> tuple[Any, ...]:
        """Call ``name`` on every environment (or read the attribute); one result each."""
        results, lost = self._exchange([("call", name, args, kwargs)] * self.num_envs)
        out = []
        for i, r in enumerate(results):
            if r[0] != "call":
                raise RuntimeError(f"env {i}: {name} failed: {r[1]}")
            out.append(r[1])
        return tuple(out)

    def get_attr(self, name: str) -> tuple[Any, ...]:
        return self.call(name)

    def render(self) -> tuple[Any, ...] | None:
        return self.call("render")

    def close_extras(self, **kwargs: Any) -> None:
        for w in self.workers:
            if w is not None:
                w.close()
        if self._ray_started:
            import ray

            ray.shutdown()

    # close() is VectorEnv's own; serve.client repeats __del__ so the HTTP client never imports eb_core.gym.
    def __del__(self) -> None:
        if not getattr(self, "closed", True):
            try:
                self.close()
            except Exception:
                pass


def _refuse_in_bootstrapping_worker() -> None:
    """A worker process that is still importing the user's script must not build vector envs of its own: that
    is a script without the ``__main__`` guard. Say so in one line instead of a traceback from every worker."""
    import multiprocessing

    if getattr(multiprocessing.current_process(), "_inheriting", False):
        raise SystemExit("eb: a worker process re-ran the script that builds the vector env; put that code under "
                         "`if __name__ == \"__main__\":` (spawn and forkserver workers import the script again)")


def make_vector_env(world: str | None, num_envs: int, *, workers: int | None = None, executor: str = "local",
                    context: str | None = "forkserver", autoreset_mode: str = "NextStep",
                    env_fns: list[Callable[[], gymnasium.Env]] | None = None, step_timeout_s: float | None = None,
                    ray_options: dict[str, Any] | None = None, ray_address: str | None = None,
                    **kwargs: Any) -> EBVectorEnv:
    """``num_envs`` copies of ``world`` (an id or env name) with ``kwargs`` for :class:`EBEnv`, over ``workers``
    processes (default: the config's ``runner.workers``, which ``overrides=("runner.workers=4",)`` sets), each
    holding ``num_envs / workers`` environments; ``executor="ray"`` makes the workers Ray actors.

    As with any non-fork start method, a script must build the vector env under ``if __name__ == "__main__":``.
    ``context="fork"`` is faster to start and safe when this process has not rendered yet."""
    if num_envs < 1:
        raise ValueError(f"num_envs must be >= 1, got {num_envs}")
    if env_fns is None:
        if world is None:
            raise ValueError("make_vector_env needs a world (an id such as 'EB/Navigation-v0' or an env name) "
                             "or env_fns")
        from eb_core.gym.ids import registered_ids

        gid = _resolve(world)
        from eb_core.gym.env import _compose

        env_fns = [_MakeEnv(gid, registered_ids()[gid], dict(kwargs))] * num_envs
        # a config error is reported here, in one line, not from inside the workers
        cfg = _compose(registered_ids()[gid], tuple(kwargs.get("overrides", ())))
        if workers is None:
            workers = int(cfg.runner.workers)
    elif len(env_fns) != num_envs:
        raise ValueError(f"env_fns has {len(env_fns)} factories but num_envs is {num_envs}")
    return EBVectorEnv(env_fns, workers=1 if workers is None else workers, executor=executor, context=context,
                       autoreset_mode=autoreset_mode, step_timeout_s=step_timeout_s, ray_options=ray_options,
                       ray_address=ray_address)
