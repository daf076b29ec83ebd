"""Episode videos: ``eb export RUN --format video [--gif] [--out DIR]``.

Each episode is replayed in its world from its task and seed, executing the recorded actions with rendering on
(the worlds are deterministic, so these are the run's own frames): the start, then one frame after every executed
action, captioned with the planner step, the action and the world's feedback. The frames the model was shown (the
state at each planner call) are marked "model's view". A replay that disagrees with the record (an action's
success or feedback) stops that episode's video with one line instead of showing something that did not happen.

MP4 (H.264) is written with imageio and the ffmpeg binary that the ``imageio-ffmpeg`` wheel ships; ``--gif`` writes
an animated GIF with Pillow instead (no ffmpeg). One frame per second; by default the file goes next to the
episode's steps (``episodes/<id>/episode.mp4``), where ``eb show`` embeds it.
"""

from __future__ import annotations

import json
import textwrap
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from eb_core.records import StepRecord, read_steps

__all__ = ["VIDEO_NAMES", "episode_frames", "write_videos"]

VIDEO_NAMES = ("episode.mp4", "episode.gif")
"""File names of an episode's video in its step folder (the viewer looks for these)."""
_FPS = 1
_CAPTION_PX = 78


@dataclass
class Frame:
    image: np.ndarray
    caption: str
    model_view: bool = False


def _caption(image: np.ndarray, text: str, model_view: bool) -> np.ndarray:
    from PIL import Image, ImageDraw, ImageFont

    h, w = image.shape[:2]
    width = max(16, (w + 15) // 16 * 16)
    height = (h + _CAPTION_PX + 15) // 16 * 16  # H.264 wants sizes divisible by 16
    canvas = Image.new("RGB", (width, height), (20, 24, 28))
    canvas.paste(Image.fromarray(np.asarray(image, dtype=np.uint8)), (0, 0))
    draw = ImageDraw.Draw(canvas)
    try:
        font = ImageFont.load_default(size=13)
    except TypeError:  # Pillow < 10.1
        font = ImageFont.load_default()
    lines = textwrap.wrap(text, width=max(20, width // 7))[:4]
    if model_view:
        draw.rectangle([0, 0, width - 1, h - 1], outline=(59, 130, 246), width=3)
    for k, line in enumerate(lines):
        draw.text((6, h + 4 + 17 * k), line, fill=(235, 238, 242), font=font)
    return np.asarray(canvas)


def _primary(obs: Any) -> np.ndarray | None:
    img = getattr(obs, "primary_image", None)
    img = img() if callable(img) else img
    return None if img is None else np.asarray(img)


def episode_frames(env: Any, task: Any, seed: int, steps: list[StepRecord]) -> tuple[list[Frame], str | None]:
    """Replay one episode with rendering; returns its captioned frames and, if the replay left the record, why."""
    obs = env.reset(task, seed)
    frames: list[Frame] = []
    first = _primary(obs)
    if first is not None:
        frames.append(Frame(first, f"{task.id}: {task.instruction}", model_view=True))
    for step in steps:
        n = step.planner_step
        if not step.actions:
            answer = "no usable plan" if step.error else "empty plan"
            if frames:
                frames.append(Frame(frames[-1].image, f"planner step {n}: {answer}", model_view=True))
            continue
        for j, act in enumerate(step.actions):
            result = env.step(act.action)
            if bool(result.action_success) != bool(act.success) or (result.feedback or "") != (act.feedback or ""):
                return frames, (f"planner step {n} action {j + 1}: the replay gave "
                                f"{'success' if result.action_success else 'failure'} ({result.feedback!r}), the "
                                f"record {act.feedback!r}; the video stops there")
            img = _primary(result.observation)
            if img is None:
                continue
            mark = "ok" if act.success else "FAILED"
            name = act.action_name or json.dumps(act.action)
            frames.append(Frame(img, f"planner step {n} · env step {act.env_step} · {name} · {mark}: "
                                     f"{act.feedback}", model_view=j == len(step.actions) - 1))
    return frames, None


def _write(path: Path, frames: list[Frame], gif: bool) -> None:
    images = [_caption(f.image, f.caption, f.model_view) for f in frames]
    if gif:
        from PIL import Image

        pil = [Image.fromarray(im) for im in images]
        pil[0].save(path, save_all=True, append_images=pil[1:], duration=int(1000 / _FPS), loop=0)
        return
    import imageio.v2 as imageio

    writer = imageio.get_writer(path, fps=_FPS, codec="libx264", quality=7, macro_block_size=16,
                                ffmpeg_log_level="error", output_params=["-pix_fmt", "yuv420p"])
    try:
        for im in images:
            writer.append_data(im)
    finally:
        writer.close()


def write_videos(run_dir: str | Path, *, out: str | Path | None = None, gif: bool = False,
                 overwrite: bool = False, tasks: list[str] | None = None) -> tuple[list[Path], list[str]]:
    """Write one video per finished episode of ``run_dir``; returns the files and one line per problem."""
    import yaml

    from eb_core.config import RunConfig
    from eb_core.plugins import Registry
    from eb_core.records import RunFiles, episode_dir_name
    from eb_core.runner import Components, select_tasks

    if not gif:
        try:
            import imageio  # noqa: F401
            import imageio_ffmpeg  # noqa: F401
        except ImportError as exc:
            raise RuntimeError(f"MP4 needs imageio and imageio-ffmpeg ({exc.name} is missing): pip install "
                               f"'embodiedbench[report]', or use --gif") from None
    root = Path(run_dir)
    cfg = RunConfig.model_validate(yaml.safe_load((root / "config.yaml").read_text(encoding="utf-8")))
    comps = Components(cfg, Registry.create())
    by_id = {t.id: t for t in select_tasks(comps.load_tasks(), cfg.model_copy(update={"tasks": None, "limit": None,
                                                                                      "sample": None,
                                                                                      "subset": None}))}
    files, problems = [], []
    env = comps.make_env()
    name = VIDEO_NAMES[1] if gif else VIDEO_NAMES[0]
    try:
        for rec in RunFiles(root).load_episodes():
            if rec.status != "ok" or (tasks and rec.task_id not in tasks):
                continue
            ep = episode_dir_name(rec.task_id, rec.repeat)
            steps_file = root / "episodes" / ep / "steps.jsonl"
            if rec.task_id not in by_id or not steps_file.is_file():
                problems.append(f"{ep}: no task or no steps.jsonl; skipped")
                continue
            target = (Path(out) / f"{ep}{Path(name).suffix}") if out else steps_file.parent / name
            if target.exists() and not overwrite:
                problems.append(f"{target} exists; pass --overwrite to replace it")
                continue
            try:
                steps = read_steps(steps_file.parent, strict=True)
            except ValueError as exc:
                problems.append(f"{ep}: {exc}")
                continue
            frames, why = episode_frames(env, by_id[rec.task_id], rec.seed, steps)
            if why:
                problems.append(f"{ep}: {why}")
            if not frames:
                problems.append(f"{ep}: the world renders no image (env.params.render=false?); no video")
                continue
            target.parent.mkdir(parents=True, exist_ok=True)
            _write(target, frames, gif)
            files.append(target)
    finally:
        env.close()
    return files, problems


def cmd_video(args: list[str]) -> int:
    """``eb export RUN --format video [--gif] [--out DIR] [--overwrite]``."""
    import sys

    from eb_core._export_flags import FlagError, parse_flags

    usage = "usage: eb export RUN --format video [--gif] [--out DIR] [--overwrite]"
    try:
        runs, opts = parse_flags(args, fmt="video", switches=("--gif", "--overwrite"))
    except FlagError as exc:
        print(f"eb export: {exc}; {usage}", file=sys.stderr)
        return 2
    if len(runs) > 1:
        print(f"eb export: --format video takes one run directory; {usage}", file=sys.stderr)
        return 2
    run = runs[0] if runs else None
    out = opts["--out"] if isinstance(opts["--out"], str) else None
    gif, overwrite = bool(opts["--gif"]), bool(opts["--overwrite"])
    if run is None or not (Path(run) / "episodes.jsonl").is_file():
        print(f"eb export: {run!r} is not a run directory (no episodes.jsonl); {usage}", file=sys.stderr)
        return 2
    try:
        files, problems = write_videos(run, out=out, gif=gif, overwrite=overwrite)
    except (RuntimeError, ValueError) as exc:
        print(f"eb export: {str(exc).splitlines()[0]}", file=sys.stderr)
        return 2
    for p in problems:
        print(f"eb export: {p}", file=sys.stderr)
    print(f"{len(files)} video(s) written" + (f" into {out}" if out else " next to the episodes' steps"))
    return 0 if files or not problems else 1
