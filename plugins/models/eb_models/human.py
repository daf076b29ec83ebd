"""The ``human`` backend: a person plays in the terminal.

Each request's image(s) are written as PNG files whose paths are printed (open them in any viewer),
then the prompt (action list, history with feedback) is printed and action ids are read from stdin.
Discrete worlds: ids separated by spaces or commas (``3 7 1``). Vector worlds: one action per ``;``,
its integers separated by commas or spaces (``50,40,30,60,60,60,1; 50,40,20,60,60,60,0``). An empty line
or end of input answers an empty plan. Use it with ``runner.workers=1``.
"""

from __future__ import annotations

import multiprocessing
import re
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, TextIO

from eb_core.env import Action, DiscreteActionSpace, PlanItemError
from eb_core.model import EpisodeContext, ImagePart, ModelBackend, ModelFatalError, ModelRequest, ModelResponse, Usage
from eb_models._answer import planner_answer
from eb_models._settings import BackendSettings, ModelConfigError, validate_settings

__all__ = ["HumanBackend", "HumanSettings"]


class HumanSettings(BackendSettings):
    image_dir: str | None = None
    """Where the images are written (default: a new temporary directory)."""
    show_prompt: bool = True
    """Print the whole prompt; when false only the action list and the instruction."""


class HumanBackend(ModelBackend):
    supports_images = True
    supports_json_schema = False

    def __init__(self, *, stdin: TextIO | None = None, stdout: TextIO | None = None, **kwargs: Any) -> None:
        self.settings = validate_settings(HumanSettings, "human", kwargs)
        if stdin is None and multiprocessing.parent_process() is not None:
            raise ModelConfigError("the human backend reads your terminal, which worker processes do not have: "
                                   "run it with runner.workers=1")
        self.stdin = stdin if stdin is not None else sys.stdin
        self.stdout = stdout if stdout is not None else sys.stdout
        self.image_dir = Path(self.settings.image_dir) if self.settings.image_dir else None
        self.ctx: EpisodeContext | None = None
        self.turn = 0

    def _say(self, text: str = "") -> None:
        print(text, file=self.stdout, flush=True)

    def start_episode(self, ctx: EpisodeContext) -> None:
        self.ctx = ctx
        self.turn = 0
        self._say(f"\n=== Task {ctx.task.id} ({ctx.task.subset}): {ctx.task.instruction}")

    def _write_images(self, request: ModelRequest) -> list[Path]:
        if self.image_dir is None:
            self.image_dir = Path(tempfile.mkdtemp(prefix="eb_human_"))
        self.image_dir.mkdir(parents=True, exist_ok=True)
        task = self.ctx.task.id if self.ctx else "task"
        paths = []
        images = [p for m in request.messages[-1:] for p in m.content if isinstance(p, ImagePart)]
        for i, img in enumerate(images):
            name = re.sub(r"[^A-Za-z0-9_.-]+", "_", img.name or f"image{i}")
            path = self.image_dir / f"{task}_turn{self.turn:03d}_{i}_{name}.png"
            path.write_bytes(img.png)
            paths.append(path)
        return paths

    def _parse(self, line: str) -> list[Action]:
        assert self.ctx is not None
        space = self.ctx.env.action_space()
        line = line.strip()
        if not line:
            return []
        if isinstance(space, DiscreteActionSpace):
            return [space.parse_plan_item(tok) for tok in re.split(r"[\s,]+", line) if tok]
        plan: list[Action] = []
        for chunk in line.split(";"):
            values = [tok for tok in re.split(r"[\s,\[\]]+", chunk) if tok]
            if not values:
                continue
            try:
                ints = [int(v) for v in values]
            except ValueError:
                raise PlanItemError(f"{chunk.strip()!r} is not a list of integers") from None
            plan.append(space.parse_plan_item(ints))
        return plan

    def complete(self, request: ModelRequest) -> ModelResponse:
        t0 = time.perf_counter()
        if self.ctx is None:
            raise ModelFatalError("the human backend needs an episode: start_episode() was not called")
        self.turn += 1
        space = self.ctx.env.action_space()
        for path in self._write_images(request):
            self._say(f"[image] {path}")
        if self.settings.show_prompt:
            self._say(request.messages[-1].text)
        else:
            self._say(space.describe())
            self._say(f"Instruction: {self.ctx.task.instruction}")
        if isinstance(space, DiscreteActionSpace):
            ask = "Your plan: action ids separated by spaces (empty line = empty plan): "
        else:
            ask = "Your plan: actions separated by ';', each as comma-separated integers (empty line = empty plan): "
        plan: list[Action] = []
        while True:
            self.stdout.write(ask)
            self.stdout.flush()
            line = self.stdin.readline()
            if not line:  # end of input
                self._say("\n(end of input: empty plan)")
                break
            try:
                plan = self._parse(line)
                break
            except PlanItemError as exc:
                self._say(f"Not a valid plan: {exc}. Try again.")
        text = planner_answer(space, plan, seen="(seen by a person)", reasoning="Chosen by a person at the terminal.")
        return ModelResponse(text=text, usage=Usage(latency_s=time.perf_counter() - t0, calls=1), model="human")

    def close(self) -> None:
        self.ctx = None
