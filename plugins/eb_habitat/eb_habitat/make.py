"""``eb tasks generate env=habitat ...``: test-style task files (:mod:`eb_habitat.generate`) or tasks of a
generated ``train``/``val`` split (:mod:`eb_habitat.splits`), whichever ``split=`` asks for.

Its own module so that the generator and the splits, which draws with the generator's builders, do not import
each other.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["generate"]


def generate(out: str | None = None, seed: int = 0, per_subset: int = 50, subset: str | None = None,
             split: str = "test", n: int | None = None, start: int = 0, difficulty: str = "classic",
             **kwargs: Any) -> list[str]:
    """Write task files and return their paths.

    ``split=test`` (default): :func:`eb_habitat.generate.generate` (``out``, ``seed``, ``per_subset``,
    ``subset``). ``split=train|val n=N [start=K] out=DIR``: tasks ``K .. K+N-1`` of that generated split (disjoint
    from the shipped test tasks), for ``eb run env=habitat env.params.task_file=DIR``.

    ``difficulty=classic|medium|hard`` picks the generator level for both (:mod:`eb_habitat.hard`; progress on
    stderr); with ``split=test`` and no ``out``, ``hard`` rewrites the shipped ``tasks/hard/`` files.
    """
    from eb_habitat.hard import DIFFICULTIES

    difficulty = str(difficulty)
    if difficulty not in DIFFICULTIES:
        raise ValueError(f"habitat: unknown difficulty {difficulty!r}; allowed: {', '.join(DIFFICULTIES)}. "
                         f"Fix: difficulty=hard (or classic, medium)")
    if split == "test" and difficulty != "classic":
        from eb_habitat.hard import write

        return write(out=out, seed=seed, per_subset=per_subset, subset=subset, difficulty=difficulty)
    if split == "test":
        from eb_habitat.generate import generate as generate_test

        return generate_test(out=out, seed=seed, per_subset=per_subset, subset=subset, **kwargs)
    from eb_habitat.splits import SPLITS, write_split

    if split not in SPLITS:
        raise ValueError(f"unknown split {split!r}; allowed: test (the shipped tasks), {', '.join(SPLITS)}")
    if out is None or n is None or int(n) < 1:
        raise ValueError(f"split={split} needs n=<tasks, >= 1> and out=<folder> (the shipped tasks/ folder "
                         f"holds the test split only)")
    return [str(p) for p in write_split(str(Path(out)), split, int(n), int(start), difficulty=difficulty)]
