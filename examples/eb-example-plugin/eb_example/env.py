"""The grid world: the agent (red) walks to the goal (green) with four moves."""

from __future__ import annotations

import numpy as np

from eb_core import DiscreteActionSpace, Env, ObjectInfo, Observation, PromptParts, StepResult, Task

MOVES = {"move up": (0, -1), "move down": (0, 1), "move left": (-1, 0), "move right": (1, 0)}


class GridWorld(Env):
    name = "gridworld"

    def __init__(self, resolution: int = 100, multi_view: bool = False, size: int = 5) -> None:
        self.resolution, self.size = resolution, size
        self.agent = (0, 0)
        self.goal = (0, 0)

    @classmethod
    def load_tasks(cls, size: int = 5) -> list[Task]:
        tasks = []
        for subset, dist in (("base", 2), ("far", 5)):
            for i in range(6):
                start = (i % size, 0)
                goal = (start[0], min(size - 1, dist)) if dist < size else (size - 1 - start[0] % 2, size - 1)
                tasks.append(Task(id=f"{subset}-{i}", subset=subset, instruction="Walk onto the green cell.",
                                  metadata={"start": list(start), "goal": list(goal)}))
        return tasks

    def _obs(self) -> Observation:
        cell = self.resolution // self.size
        img = np.full((self.resolution, self.resolution, 3), 235, np.uint8)
        gx, gy = self.goal
        ax, ay = self.agent
        img[gy * cell:(gy + 1) * cell, gx * cell:(gx + 1) * cell] = (40, 180, 60)
        img[ay * cell + 3:(ay + 1) * cell - 3, ax * cell + 3:(ax + 1) * cell - 3] = (220, 40, 40)
        return Observation(
            images={"top": img}, primary="top",
            text=f"You stand at column {ax}, row {ay}; the green cell is at column {gx}, row {gy}.",
            objects=[ObjectInfo(name="goal", box=(gx * cell, gy * cell, (gx + 1) * cell - 1, (gy + 1) * cell - 1),
                                is_target=True)],
        )

    def reset(self, task: Task, seed: int) -> Observation:
        self.agent = tuple(task.metadata["start"])
        self.goal = tuple(task.metadata["goal"])
        return self._obs()

    def step(self, action) -> StepResult:
        name = list(MOVES)[int(action)]
        dx, dy = MOVES[name]
        x, y = self.agent[0] + dx, self.agent[1] + dy
        ok = 0 <= x < self.size and 0 <= y < self.size
        if ok:
            self.agent = (x, y)
        solved = self.agent == self.goal
        return StepResult(observation=self._obs(), action_success=ok,
                          feedback="You moved." if ok else "A wall blocks that way.",
                          done=solved, task_success=solved, progress=1.0 if solved else 0.0)

    def action_space(self) -> DiscreteActionSpace:
        return DiscreteActionSpace(actions=tuple(MOVES))

    def prompt_parts(self) -> PromptParts:
        return PromptParts(
            role="You are a robot on a grid seen from above. You are the red square.",
            action_rules="Each move goes one cell; walls stop you.",
            guidelines=("Plan the whole path at once.",),
            examples=('Instruction: Walk onto the green cell.\n{"visual_state_description": "green cell two rows below",'
                      ' "reasoning_and_reflection": "go down twice", "language_plan": "down, down",'
                      ' "executable_plan": [{"action_id": 1, "action_name": "move down"},'
                      ' {"action_id": 1, "action_name": "move down"}]}',),
        )

    def expert_plan(self) -> list[int]:
        (ax, ay), (gx, gy) = self.agent, self.goal
        names = list(MOVES)
        plan = [names.index("move right" if gx > ax else "move left")] * abs(gx - ax)
        plan += [names.index("move down" if gy > ay else "move up")] * abs(gy - ay)
        return plan
