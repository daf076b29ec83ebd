"""The blind probes: policies that never look at the image must not solve tasks.

* ``blind_policies``: fixed action sequences that ignore image, instruction and feedback (always the same
  action, turn once then forward, short cycles, fixed vectors, plus the world's named ones);
* ``feedback_policies``: policies that still ignore the image but react to what the env answers, as a model
  told nothing about the scene can: walk forward and turn or side-step after a failed move; or try the
  candidates of one kind of action (``find a ...``, ``pick up the ...``) one after another, the ones whose
  names share words with the instruction first, moving to the next candidate after a failure; or fetch the
  instruction's object to the instruction's place, searching the places one by one.

Both hold every policy to at most :data:`BLIND_MAX_SUCCESS` success in every subset.
"""

from __future__ import annotations

import itertools
import random
import re
from collections import Counter, defaultdict
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from eb_core.audit.contract import BlindPolicy, FeedbackPolicy, ProbeResult
from eb_core.audit.playing import _Job, play_jobs
from eb_core.audit.setup import AuditSetup, _by_subset, _listed, _pct, _reset_seed, random_vector
from eb_core.env import Action, ActionSpace, DiscreteActionSpace, Env, StepResult, Task

__all__ = ["BLIND_MAX_SUCCESS", "CandidateSearch", "FetchSearch", "ReactivePolicy", "feedback_policies", "probe_blind_policies",
           "probe_feedback_policies"]

BLIND_MAX_SUCCESS = 0.05

_TURN = re.compile(r"\b(turn|rotate)\b", re.I)
_FORWARD = re.compile(r"\b(forward|ahead)\b", re.I)
_SIDESTEP = re.compile(r"\b(sideways|strafe|leftward|rightward)\b", re.I)
_SIDES = re.compile(r"\b(left|right)\b", re.I)


def _blind_policies(setup: AuditSetup, spaces: dict[str, ActionSpace]) -> list[BlindPolicy]:
    rng = random.Random(f"eb-audit-blind:{setup.seed}")
    n_cycles = 12 if setup.quick else 24
    policies: list[BlindPolicy] = []
    first = next(iter(spaces.values()), None)
    if isinstance(first, DiscreteActionSpace):
        policies += _discrete_blind_policies(_ranked_actions(spaces, rng), rng, n_cycles)
    elif first is not None:  # vector space: a few fixed vectors and cycles of them
        vec_rng = random.Random(f"eb-audit-vectors:{setup.seed}")
        mid = tuple((lo + hi) // 2 for lo, hi in zip(first.low, first.high))
        vectors = [mid] + [random_vector(first, vec_rng) for _ in range(5)]
        policies += [BlindPolicy(f"always {list(v)}", (v,)) for v in vectors]
        for j in range(n_cycles // 4):
            k = 2 + j % 3
            c = tuple(random_vector(first, vec_rng) for _ in range(k))
            policies.append(BlindPolicy(f"cycle of {k} fixed vectors #{j + 1}", c))
    extra = setup.blind_policies
    if extra is None:
        extra = list(setup.env_cls.audit_blind_policies())
    return policies + list(extra)


def _ranked_actions(spaces: dict[str, ActionSpace], rng: random.Random) -> list[str]:
    """Action names by how many episodes offer them (ties in a seeded random order)."""
    freq: Counter[str] = Counter()
    for sp in spaces.values():
        if isinstance(sp, DiscreteActionSpace):
            freq.update(list(dict.fromkeys(sp.actions)))  # in list order: no set order (hash seeds differ)
    return sorted(freq, key=lambda a: (-freq[a], rng.random()))


def _discrete_blind_policies(ranked: list[str], rng: random.Random, n_cycles: int) -> list[BlindPolicy]:
    constant = ranked if len(ranked) <= 16 else ranked[:16]
    policies = [BlindPolicy(f"always '{a}'", (a,)) for a in constant]
    turns = [a for a in ranked if _TURN.search(a)]
    forwards = [a for a in ranked if _FORWARD.search(a)]
    policies += [BlindPolicy(f"'{t}' once, then '{f}'", (f,), (t,)) for t in turns for f in forwards]
    pool = ranked[:8]
    seen: set[tuple[str, ...]] = set()
    all_cycles = [c for k in (2, 3, 4) for c in _cycles(pool, k)]
    if len(all_cycles) > n_cycles:
        all_cycles = rng.sample(all_cycles, n_cycles)
    for c in all_cycles:
        if c not in seen:
            seen.add(c)
            policies.append(BlindPolicy("cycle " + " > ".join(f"'{a}'" for a in c), c))
    return policies


def _cycles(pool: list[str], k: int) -> list[tuple[str, ...]]:
    """Cycles of length ``k`` over ``pool`` that are not a shorter cycle repeated (one per rotation class)."""
    out = []
    for c in itertools.product(pool, repeat=k):
        if len(set(c)) < 2:
            continue
        if any(k % d == 0 and c == c[:d] * (k // d) for d in range(1, k)):
            continue
        if c != min(c[i:] + c[:i] for i in range(k)):
            continue
        out.append(c)
    return out


def _spaces(setup: AuditSetup, tasks: list[Task]) -> dict[str, ActionSpace]:
    """Each task's action space at the start (tasks whose reset fails are left out)."""
    env = setup.make_env()
    try:
        spaces: dict[str, ActionSpace] = {}
        for t in tasks:
            try:
                env.reset(t, _reset_seed(setup.seed, t.id))
                spaces[t.id] = env.action_space()
            except Exception:  # noqa: BLE001 - the closed-loop probe reports env errors
                continue
    finally:
        env.close()
    return spaces


def _policy_table(setup: AuditSetup, tasks: list[Task], policies: Sequence[Any]) -> tuple[list[dict[str, Any]],
                                                                                          list[str], tuple]:
    """Play every policy on every task: rows (policy, best subset, its success, tasks solved; worst first),
    the task ids solved by policies above the bar in subsets above the bar, and the worst (rate, policy,
    subset)."""
    pairs = [(t, pol) for t in tasks for pol in policies]
    solved: dict[str, set[str]] = defaultdict(set)  # policy name -> solved task ids
    for (t, pol), out in zip(pairs, play_jobs(setup, [_Job(t, policy=pol) for t, pol in pairs])):
        if out.success:
            solved[pol.name].add(t.id)
    groups = _by_subset(tasks)
    rows = []
    failing: list[str] = []
    worst: tuple[float, str, str] = (0.0, "", "")
    for pol in policies:
        ids = solved.get(pol.name, set())
        rates = {s: sum(t.id in ids for t in ts) / len(ts) for s, ts in groups.items()}
        best_subset = max(rates, key=lambda s: rates[s]) if rates else ""
        best = rates.get(best_subset, 0.0)
        if best > worst[0] or not worst[1]:
            worst = (best, pol.name, best_subset)
        if best > BLIND_MAX_SUCCESS:
            failing += [t.id for s, ts in groups.items() if rates[s] > BLIND_MAX_SUCCESS for t in ts if t.id in ids]
        rows.append({"policy": pol.name, "best subset": best_subset, "success": _pct(best),
                     "solved": len(ids), "_rate": best,
                     "_subsets": ", ".join(f"{s} {100 * r:.1f}" for s, r in rates.items())})
    rows.sort(key=lambda r: -r["_rate"])
    return rows, failing, worst


def _policy_result(name: str, policies: Sequence[Any], kinds: Counter[str], rows: list[dict[str, Any]],
                   failing: list[str], worst: tuple, per_subset: bool = False) -> ProbeResult:
    """The probe's result; ``per_subset`` adds each shown policy's success in every subset (in %)."""
    shown = [{k if k != "_subsets" else "per subset (%)": v for k, v in r.items()
              if k != "_rate" and (per_subset or k != "_subsets")} for r in rows[:8]]
    bad = [r for r in rows if r["_rate"] > BLIND_MAX_SUCCESS]
    mix = ", ".join(f"{v} {k}" for k, v in kinds.items())
    value = (f"{len(policies)} policies ({mix}); worst {_pct(worst[0])} ({worst[1]} on {worst[2]})" if policies
             else "no policies (no actions)")
    if bad:
        value = (f"{len(bad)} of {len(policies)} policies ({mix}) above 5 %; worst {_pct(worst[0])} "
                 f"({worst[1]} on {worst[2]})")
    return ProbeResult(name=name, passed=not bad, value=value,
                       threshold="<= 5 % success per subset, every policy", failing_tasks=_listed(failing),
                       rows=shown)


def probe_blind_policies(setup: AuditSetup) -> ProbeResult:
    tasks = setup.sampled_tasks()
    policies = _blind_policies(setup, _spaces(setup, tasks))
    rows, failing, worst = _policy_table(setup, tasks, policies)
    kinds = Counter("turn, then forward" if p.prefix else "cycle" if p.name.startswith("cycle") else
                    "constant" if p.name.startswith("always") else "named by the world" for p in policies)
    return _policy_result("blind_policies", policies, kinds, rows, failing, worst)


# -- policies that react to feedback -------------------------------------------------------------------------


@dataclass(frozen=True)
class ReactivePolicy:
    """Play ``cycle`` over and over; after a failed action play ``on_fail[k - 1]`` instead, ``k`` being the
    number of failures in a row (the last entry repeats), then go on with the cycle. Items are action names.

    ``ReactivePolicy("...", ("Move forward",), ("Move sideways to the right", "Turn right"))`` walks forward,
    side-steps on a bump, and turns when the side-step bumps too."""

    name: str
    cycle: tuple[str, ...]
    on_fail: tuple[str, ...]

    def policy(self, task: Task | None = None) -> FeedbackPolicy:
        return _Reactive(self)


class _Reactive(FeedbackPolicy):
    def __init__(self, spec: ReactivePolicy) -> None:
        self.spec, self.fails, self.pos = spec, 0, 0

    def __call__(self, env: Env, i: int) -> Action | None:
        space = env.action_space()
        if not isinstance(space, DiscreteActionSpace):
            return None
        if self.fails:
            name = self.spec.on_fail[min(self.fails, len(self.spec.on_fail)) - 1]
        else:
            name = self.spec.cycle[self.pos % len(self.spec.cycle)]
            self.pos += 1
        return space.actions.index(name) if name in space.actions else None

    def observe(self, result: StepResult) -> None:
        self.fails = 0 if result.action_success else self.fails + 1


class _Chunks(FeedbackPolicy):
    """Plays chunks of action names in turn; a failed action, a missing name or a finished chunk moves on to the
    next chunk. ``chunks(names, instruction)`` makes them from the episode's action list at the first step."""

    def __init__(self, chunks: Any, instruction: str) -> None:
        self.make, self.instruction = chunks, instruction
        self.chunks: list[tuple[str, ...]] | None = None
        self.k, self.step = 0, 0

    def __call__(self, env: Env, i: int) -> Action | None:
        space = env.action_space()
        if not isinstance(space, DiscreteActionSpace):
            return None
        if self.chunks is None:
            self.chunks = [c for c in self.make(list(space.actions), self.instruction) if c]
        while self.k < len(self.chunks) and self.chunks[self.k][self.step] not in space.actions:
            self.k, self.step = self.k + 1, 0
        if self.k >= len(self.chunks):
            return None
        return space.actions.index(self.chunks[self.k][self.step])

    def observe(self, result: StepResult) -> None:
        assert self.chunks is not None
        self.step += 1
        if not result.action_success or self.step >= len(self.chunks[self.k]):
            self.k, self.step = self.k + 1, 0


@dataclass(frozen=True)
class CandidateSearch:
    """Skill worlds: for each candidate object in turn, play one action of every kind in ``kinds`` on it (``find
    a``, then ``pick up the``); a failed action moves on to the next candidate, and so does a finished round.
    Candidates are the objects the episode's action list offers for every kind, those whose names share
    words with the instruction first (list order otherwise): what a model that reads only the instruction, the
    action list and the feedback can do without looking."""

    name: str
    kinds: tuple[str, ...]

    def policy(self, task: Task | None = None) -> FeedbackPolicy:
        return _Chunks(self.chunks, task.instruction if task is not None else "")

    def chunks(self, names: list[str], instruction: str) -> list[tuple[str, ...]]:
        have = set(names)
        objects = [n[len(self.kinds[0]):] for n in names if n.startswith(self.kinds[0])]
        order = _guided(instruction, [o for o in objects if all(k + o in have for k in self.kinds)])
        return [tuple(k + o for k in self.kinds) for o in order]


_LOCATE = re.compile(r"^(find|navigate to|go to|walk to)\b", re.I)
_TAKE = re.compile(r"^(pick up|take|grab)\b", re.I)
_PUT = re.compile(r"^(put|place|drop)\b", re.I)


@dataclass(frozen=True)
class FetchSearch:
    """Skill worlds with go-to, pick-up and put actions: the fetch a blind model plays from the instruction alone.
    It picks up the object the instruction names (the pick-up action sharing most words with it) and brings it to
    the place the instruction names: go to each candidate place in turn (the instances of the object's type when
    the go-to list has them, ``find a Mug_2``; else every place), pick up, go to the destination, put down. A
    failed action moves on to the next place, and so does a delivery that did not end the episode (a wrong
    instance shows itself)."""

    name: str = "fetch: go to each place in turn, pick up the instruction's object, put it at its destination"

    def policy(self, task: Task | None = None) -> FeedbackPolicy:
        return _Chunks(self.chunks, task.instruction if task is not None else "")

    @staticmethod
    def chunks(names: list[str], instruction: str) -> list[tuple[str, ...]]:
        locate = [n for n in names if _LOCATE.search(n)]
        take = _guided(instruction, [n for n in names if _TAKE.search(n)], _object_of)
        put = [n for n in names if _PUT.search(n)]
        if not (locate and take and put):
            return []
        obj = _squash(_object_of(take[0]))
        same = [n for n in locate if _squash(re.sub(r"_\d+$", "", _object_of(n))) == obj]
        others = [n for n in locate if n not in same]
        dest = _guided(instruction, others, _object_of)[0] if others else locate[0]
        drop = _guided(_object_of(dest), _guided(instruction, put, _object_of), _object_of)[0]
        return [(place, take[0], dest, drop) for place in same or locate]


def _object_of(name: str) -> str:
    """What an action acts on: the words after its kind (``"Mug_2"`` of ``"find a Mug_2"``)."""
    kind = _kind(name)
    return name[len(kind):] if kind else name


_WORD = re.compile(r"[a-z]+")


def _squash(text: str) -> str:
    return "".join(_WORD.findall(text.lower()))


def _guided(instruction: str, objects: list[str], key: Any = None) -> list[str]:
    """``objects`` by how much of ``instruction`` their names cover (list order among equals): the letters of a
    name found whole in the instruction's letters (``SideTable`` in "the side table"), else the letters of its
    words found among the instruction's words. ``key`` maps an item to the name scored (default: itself)."""
    words = set(_WORD.findall(instruction.lower()))
    squashed = _squash(instruction)

    def score(item: str) -> int:
        name = re.sub(r"_\d+$", "", key(item) if key else item)
        whole = _squash(name)
        if len(whole) > 2 and whole in squashed:
            return len(whole)
        return sum(len(w) for w in _WORD.findall(name.lower()) if len(w) > 2 and w != "the" and w in words)

    return sorted(objects, key=lambda o: -score(o))


_ARTICLES = ("a", "an", "the")


def _kind(name: str) -> str:
    """An action's kind, with the space after it: its words up to an article among the first three (``"pick up
    the "``, ``"find a "``), else its first two words (``"press 1 "``); ``""`` for shorter names."""
    parts = name.split(" ")
    for k in range(1, min(3, len(parts) - 1) + 1):
        if parts[k - 1].lower() in _ARTICLES:
            return " ".join(parts[:k]) + " "
    return " ".join(parts[:2]) + " " if len(parts) > 2 else ""


def feedback_policies(ranked: list[str]) -> list[ReactivePolicy | CandidateSearch | FetchSearch]:
    """The policies of ``feedback_policies`` for a discrete action list (names by frequency): movement worlds
    (a forward action and turns or side-steps) get walk-forward policies that turn or side-step after a failed
    move; skill worlds (kinds of action with several objects each) get the fetch (:class:`FetchSearch`, when they
    have go-to, pick-up and put actions) and candidate searches over their four most frequent kinds, alone and in
    ordered pairs."""
    out: list[ReactivePolicy | CandidateSearch | FetchSearch] = []
    forwards = [a for a in ranked if _FORWARD.search(a)]
    turns = [a for a in ranked if _TURN.search(a) and _SIDES.search(a)]
    steps = [a for a in ranked if _SIDESTEP.search(a) and _SIDES.search(a) and not _TURN.search(a)]
    for f in forwards[:1]:
        out += [ReactivePolicy(f"'{f}'; after a failure '{r}'", (f,), (r,)) for r in turns + steps]
        out += [ReactivePolicy(f"'{f}'; after a failure '{s}', after two '{t}'", (f,), (s, t))
                for s in steps for t in turns]
    if out:
        return out
    kinds = Counter(_kind(a) for a in ranked if _kind(a))
    top = [k for k, n in kinds.most_common() if n >= 2][:4]
    if FetchSearch.chunks(ranked, ""):
        out.append(FetchSearch())
    out += [CandidateSearch(f"'{k.strip()} ...' on each candidate, next after a failure", (k,)) for k in top]
    out += [CandidateSearch(f"'{a.strip()} X' then '{b.strip()} X' for each candidate X, next after a failure",
                            (a, b)) for a in top for b in top if a != b]
    return out


def probe_feedback_policies(setup: AuditSetup) -> ProbeResult:
    tasks = setup.sampled_tasks()
    spaces = _spaces(setup, tasks)
    ranked = _ranked_actions(spaces, random.Random(f"eb-audit-feedback:{setup.seed}"))
    discrete = isinstance(next(iter(spaces.values()), None), DiscreteActionSpace)
    policies = feedback_policies(ranked) if discrete else []
    if not policies:
        why = "no forward move and no kinds of action with several objects" if discrete else "actions are vectors"
        return ProbeResult(name="feedback_policies", passed=True, skipped=True, value=f"n/a ({why})",
                           threshold="<= 5 % success per subset, every policy")
    rows, failing, worst = _policy_table(setup, tasks, policies)
    kinds = Counter("turn or side-step after a failure" if isinstance(p, ReactivePolicy) else
                    "fetch, next place after a failure" if isinstance(p, FetchSearch) else
                    "next candidate after a failure" for p in policies)
    result = _policy_result("feedback_policies", policies, kinds, rows, failing, worst, per_subset=True)
    if not result.passed and setup.taskset == "classic" and setup.task_file_is_shipped():
        # The paper's task sets are fixed (their files and scores must not change): this shortcut is a measured,
        # documented property of them (docs/audit.md), not something the audit can ask to be fixed. The harder
        # sets (taskset=hard) and generated files are held to the bar.
        return result.model_copy(update={
            "passed": True,
            "warning": (f"the classic task set is fixed: {result.value}. It is a known shortcut of the paper's "
                        f"tasks (docs/audit.md); taskset=hard and generated task files must pass this probe")})
    return result
