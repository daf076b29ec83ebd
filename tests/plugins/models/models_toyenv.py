"""Tiny in-test worlds for the offline backends: a discrete button line and a vector reach task."""

from __future__ import annotations

from typing import Any

import numpy as np

from eb_core import (
    DiscreteActionSpace,
    Env,
    Observation,
    PromptParts,
    StepResult,
    Task,
    VectorActionSpace,
)

LINE_ACTIONS = ("step left", "step right", "press the button")


class ButtonLine(Env):
    """Walk along a line of ``length`` cells to the button's cell and press it."""

    name = "button-line"

    def __init__(self, resolution: int = 16, multi_view: bool = False, length: int = 6) -> None:
        self.resolution, self.length = resolution, length
        self.pos = self.button = 0
        self.pressed = False

    @classmethod
    def load_tasks(cls, **params: Any) -> list[Task]:
        return [Task(id=f"line-{i}", subset="base", instruction=f"press the button at cell {2 + i}",
                     metadata={"start": i % 2, "button": 2 + i}) for i in range(3)]

    def _obs(self) -> Observation:
        img = np.zeros((self.resolution, self.resolution, 3), np.uint8)
        img[:, :, 0] = 40 * self.pos
        return Observation(images={"front": img}, primary="front",
                           text=f"You are at cell {self.pos}; the button is at cell {self.button}.")

    def reset(self, task: Task, seed: int) -> Observation:
        self.pos, self.button, self.pressed = int(task.metadata["start"]), int(task.metadata["button"]), False
        return self._obs()

    def step(self, action: Any) -> StepResult:
        name = LINE_ACTIONS[int(action)]
        ok = True
        if name == "step left":
            ok = self.pos > 0
            self.pos = max(0, self.pos - 1)
        elif name == "step right":
            ok = self.pos < self.length - 1
            self.pos = min(self.length - 1, self.pos + 1)
        else:
            ok = self.pos == self.button
            self.pressed = self.pressed or ok
        return StepResult(observation=self._obs(), action_success=ok, feedback="ok" if ok else "that did not work",
                          done=self.pressed, task_success=self.pressed, progress=1.0 if self.pressed else 0.0)

    def action_space(self) -> DiscreteActionSpace:
        return DiscreteActionSpace(actions=LINE_ACTIONS)

    def prompt_parts(self) -> PromptParts:
        return PromptParts(role="You walk along a line of cells and press a button.", guidelines=("Be quick.",))

    def expert_plan(self) -> list[int]:
        d = self.button - self.pos
        return ([1] * d if d > 0 else [0] * -d) + [2]


class VectorReach(Env):
    """Move a 3-D point with integer coordinates in [0, 10] onto the target."""

    name = "vector-reach"

    def __init__(self, resolution: int = 16, multi_view: bool = False) -> None:
        self.resolution = resolution
        self.target: tuple[int, ...] = (0, 0, 0)
        self.at: tuple[int, ...] = (0, 0, 0)

    @classmethod
    def load_tasks(cls, **params: Any) -> list[Task]:
        return [Task(id="reach-0", subset="base", instruction="reach 3 4 5", metadata={"target": [3, 4, 5]})]

    def reset(self, task: Task, seed: int) -> Observation:
        self.target, self.at = tuple(task.metadata["target"]), (0, 0, 0)
        return Observation(images={"front": np.zeros((16, 16, 3), np.uint8)}, primary="front", text="a point")

    def step(self, action: Any) -> StepResult:
        self.at = tuple(int(v) for v in action)
        ok = self.at == self.target
        return StepResult(observation=Observation(text="a point"), action_success=True, feedback="moved",
                          done=ok, task_success=ok, progress=1.0 if ok else 0.0)

    def action_space(self) -> VectorActionSpace:
        return VectorActionSpace(names=("x", "y", "z"), low=(0, 0, 0), high=(10, 10, 10))

    def prompt_parts(self) -> PromptParts:
        return PromptParts(role="Move the point.")

    def expert_plan(self) -> list[tuple[int, ...]]:
        return [self.target]


# -- registered directly in runner tests (``run(..., plugins=[models_toyenv, eb_models.plugin])``) --------

from eb_core import EnvSpec, hookimpl  # noqa: E402


@hookimpl
def eb_register_envs() -> list[EnvSpec]:
    return [EnvSpec(name="button-line", entry_point="models_toyenv:ButtonLine", subsets={"base": 3},
                    description="eb-models test world")]
