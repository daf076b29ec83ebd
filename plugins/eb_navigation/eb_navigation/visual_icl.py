"""Visual in-context examples (``ablation=visual_icl``): episodes from our own rooms, solved by the oracle.

The original shows one worked episode with a first-person image before each planning round. We ship
:data:`EPISODES` of them, rendered from rooms that are not in the task file (room seeds above the generator's
range) and solved by the oracle planner, with a walk-through written from the geometry (where the target is,
what the plan does, what the world answered). The PNGs (320 x 320) and ``examples.json`` live in
``eb_navigation/icl/`` inside the package; :func:`visual_examples` reads them once, on first use.

Rebuild them (a few seconds, needs MuJoCo): ``python -m eb_navigation.visual_icl``.
"""

from __future__ import annotations

import json
import math
from functools import lru_cache
from pathlib import Path

from eb_core.env import VisualExample

__all__ = ["EPISODES", "ICL_DIR", "build", "visual_examples"]

ICL_DIR = Path(__file__).parent / "icl"
IMAGE_SIZE = 320
#: (room kind, room seed, target type): seeds above the task generator's range (0..99,999), so never a task's room.
EPISODES: tuple[tuple[str, int, str], ...] = (
    ("living_room", 100_004, "Sofa"),
    ("kitchen", 100_000, "Fridge"),
)
_MOVE_WORDS = {0: "forward", 1: "backward", 2: "to the right", 3: "to the left"}


@lru_cache(maxsize=1)
def visual_examples() -> tuple[VisualExample, ...]:
    """The shipped examples as :class:`~eb_core.env.VisualExample` objects (PNG bytes), read on first call."""
    index = ICL_DIR / "examples.json"
    if not index.is_file():
        return ()
    doc = json.loads(index.read_text(encoding="utf-8"))
    return tuple(VisualExample(text=ex["text"], images=tuple((ICL_DIR / name).read_bytes() for name in ex["images"]))
                 for ex in doc["examples"])


def _where(bearing: float) -> str:
    if abs(bearing) <= 12:
        return "straight ahead"
    side = "left" if bearing > 0 else "right"
    return f"ahead on the {side}" if abs(bearing) <= 50 else f"on my {side}"


def _plan_words(plan: list[int]) -> str:
    from eb_navigation.geometry import ACTION_NAMES

    return ", ".join(f"[{a}] {ACTION_NAMES[a]}" for a in plan)


def _summary(plan: list[int]) -> str:
    counts: dict[str, int] = {}
    for a in plan:
        word = _MOVE_WORDS.get(a, "turn")
        counts[word] = counts.get(word, 0) + 1
    parts = [f"{w} {'once' if n == 1 else 'twice' if n == 2 else f'{n} times'}" for w, n in counts.items()]
    return "move " + " and ".join(parts)


def build(out_dir: Path = ICL_DIR) -> Path:
    """Render the example episodes and write the PNGs and ``examples.json`` into ``out_dir``."""
    from PIL import Image

    from eb_navigation.geometry import AgentState, bearing_to, distance_to
    from eb_navigation.instructions import colour_word, display_name
    from eb_navigation.room import NavRoom
    from eb_navigation.scene import RoomScene

    out_dir.mkdir(parents=True, exist_ok=True)
    examples = []
    for k, (kind, seed, type_name) in enumerate(EPISODES):
        room = NavRoom(kind, seed)
        target = next(o for o in room.objects if o.type == type_name)
        free = room.free_space()
        xy = (target.x, target.y)
        best = None
        for i, j in sorted(free.free_cells()):
            d = math.hypot(i * 0.25 - xy[0], j * 0.25 - xy[1])
            if not 2.5 <= d <= 3.5:
                continue
            for h in range(4):
                s = AgentState(i, j, h)
                b = abs(bearing_to(s, xy))
                if 12 <= b <= 40:
                    plan = free.shortest_plan(s, xy)
                    if plan and 7 <= len(plan) <= 14 and (best is None or abs(b - 25) < best[0]):
                        best = (abs(b - 25), s)
        start = best[1] if best else None
        if start is None:
            raise RuntimeError(f"no example start in {kind} {seed}")
        name = f"{colour_word(target.colour)} {display_name(target.type)}"
        scene = RoomScene(room, 500)
        images, lines = [], [f"Instruction: Go to the {display_name(target.type)}."]
        s, sizes, n_img = start, [2, 6, 6, 6], 0
        try:
            for size in sizes:
                plan = free.shortest_plan(s, xy) or []
                if not plan:
                    break
                chunk = plan[:size]
                scene.set_agent(s)
                img = Image.fromarray(scene.first_person()).resize((IMAGE_SIZE, IMAGE_SIZE), Image.Resampling.LANCZOS)
                fname = f"example{k}_step{n_img}.png"
                img.save(out_dir / fname, optimize=True)
                images.append(fname)
                n_img += 1
                d = distance_to(s, xy)
                lines.append("<image>")
                metres = max(0.5, round(d * 2) / 2)
                lines.append(f"Reasoning: The {name} is {_where(bearing_to(s, xy))}, about {metres:g} "
                             f"{'metre' if metres == 1 else 'metres'} away. I will {_summary(chunk)} toward it"
                             f"{', keeping clear of the furniture' if len(set(chunk)) > 1 else ''}.")
                lines.append("Plan: " + _plan_words(chunk))
                for a in chunk:
                    s, ok, _ = free.apply(s, a)
                    assert ok
                done = not (free.shortest_plan(s, xy) or [])
                lines.append("Feedback: every action succeeded" + (", and the episode ended: I am close to the "
                                                                    f"{display_name(target.type)}." if done else "."))
                if done:
                    break
        finally:
            scene.close()
        examples.append({"room": [kind, seed], "target": target.id, "text": "\n".join(lines), "images": images})
    index = out_dir / "examples.json"
    index.write_text(json.dumps({"examples": examples}, indent=1) + "\n", encoding="utf-8")
    visual_examples.cache_clear()
    return index


if __name__ == "__main__":
    print(build())
