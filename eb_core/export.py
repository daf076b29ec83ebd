"""``eb export RUN_DIR --out DIR``: a run's planner steps as a training/sharing dataset.

* ``--format parquet`` (default): one row per planner step (task, subset, instruction, step, prompt, images,
  raw answer, parsed plan, actions, feedback, progress, error labels) in Parquet shards under ``DIR/data/``
  that pyarrow and ``datasets.load_dataset("parquet", data_files=...)`` read directly, and a dataset card
  ``DIR/README.md`` with the run's config, model, versions and metrics.
* ``--format chat``: ``DIR/chat.jsonl``, one line per planner call in the chat form of supervised fine-tuning
  sets (LLaVA / ShareGPT style): ``images`` and ``messages`` (user: ``<image>`` markers + the prompt;
  assistant: the model's answer). A run played with ``runner.expert_labels=true`` adds the expert's action from
  the state the model saw to every line, and ``--label expert`` makes it the assistant's answer: with a noisy
  expert (``model=oracle model.noise=0.2``) the data shows recoveries from off-path states, labelled correctly.

``--images embed`` puts the PNG bytes in the rows (chat: ``data:`` URIs); ``--images paths`` (default) copies the
PNGs to ``DIR/images/<episode>/`` and stores paths relative to ``DIR``. pyarrow is imported only here.
"""

from __future__ import annotations

import base64
import json
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from eb_core.records import StepRecord, episode_dir_name, read_steps

__all__ = ["export_run", "cmd_export"]

IMAGE_MODES = ("embed", "paths")
EXPORT_FORMATS = ("parquet", "chat")
LABELS = ("model", "expert")
SHARD_ROWS = 2000


def _step_images(step: StepRecord) -> list[str]:
    """File names of the images the model was sent at this step (the primary image and any extra views)."""
    if step.sent_images is not None:
        names = [str(n) for n in step.sent_images]
        return [n for n in names if n.endswith(".png")] or ([step.image] if names and step.image else [])
    if step.image is None:
        return []
    return [step.image, *(step.extra_images or [])]


def _rows(run: dict[str, Any], images: str, out: Path, only_success: bool) -> Iterator[dict[str, Any]]:
    """One dict per planner step of the run, in episode order."""
    from eb_core.errors import label_episode, run_vocabulary

    root = Path(run["dir"])
    records = [r for r in run["records"] if r.status == "ok" and (r.success or not only_success)]
    steps_of = {r.key: read_steps(root / "episodes" / episode_dir_name(*r.key)) for r in records}
    vocab = run_vocabulary(steps_of.values())
    for rec in records:
        ep_name = episode_dir_name(*rec.key)
        steps = steps_of[rec.key]
        labels = label_episode(steps, rec.model_dump(), vocab)["steps"]
        for step, lab in zip(steps, labels):
            parsed = step.parsed
            actions = [a.model_dump(mode="json", exclude_unset=True) for a in step.actions]
            imgs: list[dict[str, Any]] = []
            for name in _step_images(step):
                src = root / "episodes" / ep_name / name
                if not src.exists():
                    continue
                if images == "embed":
                    imgs.append({"bytes": src.read_bytes(), "path": f"{ep_name}/{name}"})
                else:
                    dst = out / "images" / ep_name / name
                    dst.parent.mkdir(parents=True, exist_ok=True)
                    shutil.copyfile(src, dst)
                    imgs.append({"bytes": None, "path": f"images/{ep_name}/{name}"})
            yield {
                "env": run["env"], "model": run["model"], "ablation": run["ablation"],
                "task_id": rec.task_id, "repeat": rec.repeat, "subset": rec.subset, "instruction": rec.instruction,
                "episode_success": rec.success, "planner_step": step.planner_step,
                "prompt": step.prompt, "images": imgs, "raw_output": step.raw_output,
                "visual_state_description": parsed.visual_state_description if parsed else None,
                "reasoning_and_reflection": parsed.reasoning_and_reflection if parsed else None,
                "language_plan": parsed.language_plan if parsed else None,
                "executable_plan": json.dumps(parsed.executable_plan) if parsed else None,
                "output_error": step.error, "plan_error": step.plan_error,
                "actions": [str(a.action_name) for a in step.actions],
                "actions_json": json.dumps(actions, default=str),
                "action_success": [a.success for a in step.actions],
                "feedback": [a.feedback for a in step.actions],
                "progress": step.actions[-1].progress if step.actions else None,
                "error_labels": [x["category"] for x in lab["labels"]],
                "perception_f1": (lab.get("perception") or {}).get("f1"),
            }


def _expert_answer(action: Any, name: str | None, recovery: bool, think: bool) -> str:
    """A planner answer whose plan is the expert's one action (a vector action as ``{"action": [...]}``)."""
    item: dict[str, Any] = ({"action": list(action)} if isinstance(action, list)
                            else {"action_id": action, "action_name": name})
    why = ("An earlier action left the expert's path; this is the expert's next action from the current state."
           if recovery else "The expert's next action from the current state.")
    body = json.dumps({"visual_state_description": "", "reasoning_and_reflection": why,
                       "language_plan": name or json.dumps(action), "executable_plan": [item]})
    return f"<think>{why}</think><answer>{body}</answer>" if think else body


def _chat_lines(run: dict[str, Any], images: str, out: Path, only_success: bool, label: str) -> list[str]:
    """One JSON line per planner call. With ``runner.expert_labels`` every line names the expert's action from
    the state the model saw (``expert_action``), whether the model's first action left it (``off_expert``), and
    whether an earlier action of the episode did (``recovery``: the state is off the expert's path, and the
    expert's action shows the way back) -- the data a noisy expert (``model.noise``) is run for."""
    conf = run.get("config") or {}
    think = ((conf.get("planner") or {}).get("answer_format") if isinstance(conf, dict) else None) == "think"
    lines: list[str] = []
    left_path: dict[tuple[str, int], bool] = {}
    labelled = skipped = 0
    for row in _rows(run, images, out, only_success):
        refs = []
        for img in row["images"]:
            if img["bytes"] is not None:
                refs.append("data:image/png;base64," + base64.b64encode(img["bytes"]).decode("ascii"))
            else:
                refs.append(img["path"])
        key = (row["task_id"], row["repeat"])
        recovery = left_path.get(key, False)
        acts = json.loads(row["actions_json"])
        expert = acts[0] if acts and "expert_action" in acts[0] else None
        if any("expert_action" in a and a.get("expert_action") is not None and a["action"] != a["expert_action"]
               for a in acts):
            left_path[key] = True
        sample: dict[str, Any] = {
            "id": f"{row['task_id']}/r{row['repeat']}/step{row['planner_step']}", "task_id": row["task_id"],
            "subset": row["subset"], "planner_step": row["planner_step"], "episode_success": row["episode_success"],
            "error_labels": row["error_labels"], "images": refs}
        answer = row["raw_output"]
        if expert is not None and expert.get("expert_action") is not None:
            labelled += 1
            sample.update({"expert_action": expert["expert_action"],
                           "expert_action_name": expert.get("expert_action_name"),
                           "off_expert": acts[0]["action"] != expert["expert_action"], "recovery": recovery})
            if label == "expert":
                sample["model_answer"] = answer
                answer = _expert_answer(expert["expert_action"], expert.get("expert_action_name"), recovery, think)
        elif label == "expert":
            skipped += 1  # no executed action (an output error) or no expert plan from this state: no label
            continue
        user = "".join("<image>\n" for _ in refs) + row["prompt"]
        sample["messages"] = [{"role": "user", "content": user}, {"role": "assistant", "content": answer}]
        lines.append(json.dumps(sample, ensure_ascii=False))
    if label == "expert" and not labelled and skipped:
        raise ValueError(f"the run {run['dir']} has no expert labels to export: play it with "
                         "runner.expert_labels=true (e.g. eb run ... model=oracle model.noise=0.2 "
                         "runner.expert_labels=true)")
    return lines


def _schema() -> Any:  # a pyarrow.Schema (pyarrow is imported only by this command)
    import pyarrow as pa

    image = pa.struct([("bytes", pa.binary()), ("path", pa.string())])
    return pa.schema([
        ("env", pa.string()), ("model", pa.string()), ("ablation", pa.string()), ("task_id", pa.string()),
        ("repeat", pa.int32()), ("subset", pa.string()), ("instruction", pa.string()),
        ("episode_success", pa.bool_()), ("planner_step", pa.int32()), ("prompt", pa.string()),
        ("images", pa.list_(image)), ("raw_output", pa.string()), ("visual_state_description", pa.string()),
        ("reasoning_and_reflection", pa.string()), ("language_plan", pa.string()),
        ("executable_plan", pa.string()), ("output_error", pa.string()), ("plan_error", pa.string()),
        ("actions", pa.list_(pa.string())), ("actions_json", pa.string()), ("action_success", pa.list_(pa.bool_())),
        ("feedback", pa.list_(pa.string())), ("progress", pa.float64()), ("error_labels", pa.list_(pa.string())),
        ("perception_f1", pa.float64()),
    ])


def _with_hf_features(schema: Any, embedded: bool) -> Any:
    """``schema`` with the Hugging Face ``datasets`` feature description in its metadata (the classic
    ``Sequence`` spelling, which old and new ``datasets`` releases read): embedded images load as images; copied
    ones stay ``{bytes: None, path}`` records, since ``datasets`` would resolve their paths against the working
    directory instead of the export folder."""
    import pyarrow as pa

    def feature(t: Any) -> dict[str, Any]:
        if pa.types.is_list(t):
            return {"feature": feature(t.value_type), "_type": "Sequence"}
        if pa.types.is_struct(t):  # the image struct {bytes, path}
            if embedded:
                return {"_type": "Image"}
            return {"bytes": {"dtype": "binary", "_type": "Value"}, "path": {"dtype": "string", "_type": "Value"}}
        dtype = {pa.string(): "string", pa.int32(): "int32", pa.bool_(): "bool", pa.float64(): "float64"}[t]
        return {"dtype": dtype, "_type": "Value"}

    features = {f.name: feature(f.type) for f in schema}
    return schema.with_metadata({"huggingface": json.dumps({"info": {"features": features}})})


def _card(run: dict[str, Any], out: Path, n_rows: int, files: list[str], fmt: str, images: str) -> str:
    """The dataset card: what the rows are, where they come from (config, model, versions) and the metrics."""
    import platform

    from eb_core.report import _with_ci

    root = Path(run["dir"])
    o = run["overall"]
    split = _split_of(run)
    lines = ["---", "configs:", "- config_name: default", "  data_files:", f"  - split: {split}",
             "    path: " + ("data/*.parquet" if fmt == "parquet" else "chat.jsonl"), "---", "",
             f"# EmbodiedBench trajectories: {run['env']} / {run['model']} / {run['ablation']}", "",
             f"{n_rows} {'rows, one per planner step' if fmt == 'parquet' else 'chat samples, one per planner call'}"
             f", exported from `{root}` by `eb export` (images: {images}).", "",
             "## Metrics of the run", "", "| subset | episodes | success % [95% CI] | subgoal % [95% CI] |",
             "|---|---|---|---|"]
    for name, block in [*run["subsets"].items(), ("all", o)]:
        lines.append(f"| {name} | {block.get('episodes', 0):.0f} | {_with_ci(block, 'success_rate')} | "
                     f"{_with_ci(block, 'subgoal_success')} |")
    ea = o.get("error_analysis")
    if ea:
        lines += ["", "Automatic error labels (docs/error_analysis.md), % of episodes with the error (count):", ""]
        for key, cat in ea["categories"].items():
            if cat["count"]:
                lines.append(f"- {key}: {100 * cat['episode_rate']:.1f} % ({cat['count']:.0f})")
    versions = {}
    if (root / "plugins.json").exists():
        versions = json.loads((root / "plugins.json").read_text(encoding="utf-8"))
    try:
        import pyarrow

        versions["pyarrow"] = pyarrow.__version__
    except ImportError:  # chat export needs no pyarrow
        pass
    versions["python"] = platform.python_version()
    lines += ["", "## Versions", "", *[f"- {k}: {v}" for k, v in versions.items()]]
    if fmt == "parquet":
        lines += ["", "## Columns", "",
                  "task_id, repeat, subset, instruction, episode_success, planner_step; prompt (the text the model "
                  "was sent); images (list of {bytes, path}: bytes when embedded, else a path relative to this "
                  "folder); raw_output; visual_state_description, reasoning_and_reflection, language_plan, "
                  "executable_plan (JSON) from the parsed answer; output_error, plan_error; actions, action_success, "
                  "feedback (per executed action) and actions_json (the full action records); progress after the "
                  "step; error_labels (automatic, per step); perception_f1.", "",
                  "Read it with `pyarrow.parquet.read_table(\"data\")` or "
                  "`datasets.load_dataset(\"parquet\", data_files=\"data/*.parquet\")`."]
    lines += ["", "## Files", "", *[f"- {f}" for f in files]]
    conf = (root / "config.yaml").read_text(encoding="utf-8") if (root / "config.yaml").exists() else ""
    lines += ["", "## Run config (config.yaml)", "", "```yaml", conf.rstrip(), "```", ""]
    return "\n".join(lines)


def _split_of(run: dict[str, Any]) -> str:
    """The dataset split of a run's trajectories: the benchmark's own tasks are ``test`` (they must never be
    trained on by mistake); runs on generated splits keep theirs (``train``, ``val``)."""
    return str((run.get("config") or {}).get("split") or "test")


def export_run(run_dir: str | Path, out: str | Path, images: str = "paths", fmt: str = "parquet",
               only_success: bool = False, shard_rows: int = SHARD_ROWS, label: str = "model",
               overwrite: bool = False) -> dict[str, Any]:
    """Export ``run_dir`` into ``out``; returns ``{"rows": n, "files": [...]}`` (paths relative to ``out``).
    ``label`` (chat only): ``model`` (the assistant turn is the model's answer) or ``expert`` (the expert's
    action from the state the model saw, as a one-action answer; needs a run with ``runner.expert_labels``)."""
    from eb_core.report import load_run

    if images not in IMAGE_MODES:
        raise ValueError(f"--images {images!r}: use embed or paths")
    if fmt not in EXPORT_FORMATS:
        raise ValueError(f"--format {fmt!r}: use parquet or chat")
    if label not in LABELS:
        raise ValueError(f"--label {label!r}: use model (the model's answers) or expert (the expert's actions)")
    if label != "model" and fmt != "chat":
        raise ValueError("--label expert is for --format chat; the parquet rows carry the expert labels in "
                         "actions_json")
    out = Path(out)
    existing = [p for p in (out / "README.md", out / "chat.jsonl") if p.exists()]
    existing += sorted((out / "data").glob("*.parquet"))
    if existing and not overwrite:
        raise FileExistsError(f"{existing[0]} exists (an earlier export); choose another --out or pass --overwrite")
    for old in existing:  # --overwrite: nothing of the earlier export may be left to be read as this one
        old.unlink()
    run = load_run(run_dir)
    split = _split_of(run)
    out.mkdir(parents=True, exist_ok=True)
    files: list[str] = []
    n = 0
    if fmt == "parquet":
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq
        except ImportError:
            raise ValueError("eb export --format parquet needs pyarrow: pip install 'embodiedbench[report]' "
                             "(or pip install -r requirements.txt)") from None
        schema = _with_hf_features(_schema(), embedded=images == "embed")
        rows = list(_rows(run, images, out, only_success))
        n = len(rows)
        (out / "data").mkdir(exist_ok=True)
        for old in (out / "data").glob("*.parquet"):
            old.unlink()
        shards = max(1, -(-n // shard_rows))
        for i in range(shards):
            chunk = rows[i * shard_rows:(i + 1) * shard_rows]
            name = f"data/{split}-{i:05d}-of-{shards:05d}.parquet"
            pq.write_table(pa.Table.from_pylist(chunk, schema=schema), out / name)
            files.append(name)
    else:
        lines = _chat_lines(run, images, out, only_success, label)
        n = len(lines)
        (out / "chat.jsonl").write_text("".join(x + "\n" for x in lines), encoding="utf-8")
        files.append("chat.jsonl")
    (out / "README.md").write_text(_card(run, out, n, files, fmt, images), encoding="utf-8")
    return {"rows": n, "files": files}


def _format_asked(args: list[str]) -> str | None:
    """The value of ``--format`` among ``args`` (``--format X`` or ``--format=X``), if any."""
    for i, a in enumerate(args):
        if a.startswith("--format="):
            return a.split("=", 1)[1]
        if a == "--format" and i + 1 < len(args):
            return args[i + 1]
    return None


def _export_args(args: list[str], usage: str, error: type[Exception]) -> dict[str, Any]:
    """``eb export``'s arguments by option name (``run_dir`` for the positional one); ``error`` for bad input."""
    opts: dict[str, Any] = {"run_dir": None, "--out": None, "--images": "paths", "--format": "parquet",
                            "--label": "model", "--only-success": False, "--overwrite": False}
    it = iter(args)
    for a in it:
        key, eq, val = a.partition("=")
        if key in ("--out", "--images", "--format", "--label"):
            value = val if eq else next(it, "")
            if not value:
                raise error(f"{key} needs a value; {usage}")
            opts[key] = value
        elif a in ("--only-success", "--overwrite"):
            opts[a] = True
        elif a.startswith("-"):
            raise error(f"unknown option {a!r} for export; {usage}")
        elif opts["run_dir"] is None:
            opts["run_dir"] = a
        else:
            raise error(f"export takes one run directory (got {opts['run_dir']!r} and {a!r}); {usage}")
    return opts


def cmd_export(args: list[str]) -> int:
    """``eb export RUN_DIR --out DIR [--images embed|paths] [--format parquet|chat] [--label model|expert]
    [--only-success] [--overwrite]``."""
    from eb_core.exceptions import CliError

    fmt_asked = _format_asked(args)
    if fmt_asked == "matrix":
        from eb_core.matrix import cmd_matrix  # several runs -> one task x run table

        return cmd_matrix(args)
    if fmt_asked == "video":
        from eb_core.video import cmd_video  # replayed with rendering, captioned

        return cmd_video(args)
    usage = ("usage: eb export RUN_DIR --out DIR [--images embed|paths] [--format parquet|chat] "
             "[--label model|expert] [--only-success] [--overwrite]")
    opts = _export_args(args, usage, CliError)
    run_dir, out, images, fmt = opts["run_dir"], opts["--out"], opts["--images"], opts["--format"]
    only_success, label, overwrite = opts["--only-success"], opts["--label"], opts["--overwrite"]
    if run_dir is None or out is None:
        raise CliError(usage)
    if images not in IMAGE_MODES:
        raise CliError(f"unknown --images {images!r}; use embed (PNG bytes in the rows) or paths (files copied "
                       f"beside the data)")
    if fmt not in EXPORT_FORMATS:
        raise CliError(f"unknown --format {fmt!r}; use parquet (one row per planner step) or chat (SFT messages)")
    if not (Path(run_dir) / "episodes.jsonl").exists():
        raise CliError(f"{run_dir} is not a run directory (no episodes.jsonl)")
    try:
        result = export_run(run_dir, out, images, fmt, only_success, label=label, overwrite=overwrite)
    except (ValueError, FileExistsError) as exc:
        raise CliError(str(exc)) from None
    print(f"{result['rows']} rows -> {out} ({', '.join(result['files'])}, README.md)")
    return 0
