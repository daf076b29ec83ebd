"""``eb export RUN --format video``: one replayed, captioned video per episode, readable by ffmpeg."""

from __future__ import annotations

import json
import subprocess
import sys

import imageio.v2 as imageio
import pytest
from PIL import Image


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("video") / "run"
    p = subprocess.run([sys.executable, "-m", "eb_core", "run", "env=navigation", "model=oracle", "limit=2",
                        "runner.quiet=true", f"hydra.run.dir={d}"], capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr[-2000:]
    return d


def _actions(ep_dir):
    return sum(len(json.loads(line)["actions"]) for line in (ep_dir / "steps.jsonl").read_text().splitlines())


def _export(*args):
    return subprocess.run([sys.executable, "-m", "eb_core", "export", *map(str, args)], capture_output=True,
                          text=True, timeout=600)


def test_mp4_per_episode_with_one_frame_per_state(run_dir):
    p = _export(run_dir, "--format", "video")
    assert p.returncode == 0, p.stderr
    eps = sorted((run_dir / "episodes").iterdir())
    assert len(eps) == 2
    for ep in eps:
        reader = imageio.get_reader(ep / "episode.mp4", format="FFMPEG")  # ffmpeg decodes it
        frames = [f for f in reader]
        reader.close()
        assert len(frames) == 1 + _actions(ep)  # the start, then one frame after every action
        assert frames[0].shape[0] % 16 == 0 and frames[0].shape[1] % 16 == 0 and frames[0].mean() > 20
    again = _export(run_dir, "--format", "video")
    assert "exists; pass --overwrite" in again.stderr


def test_gif_and_a_tampered_record_stops_with_one_line(run_dir, tmp_path):
    ep = sorted((run_dir / "episodes").iterdir())[0]
    lines = (ep / "steps.jsonl").read_text().splitlines()
    first = json.loads(lines[0])
    first["actions"][1]["feedback"] = "something that never happened"
    (ep / "steps.jsonl").write_text("\n".join([json.dumps(first), *lines[1:]]) + "\n")
    p = _export(run_dir, "--format=video", "--gif", "--out", tmp_path / "gifs")
    assert p.returncode == 0, p.stderr
    assert "action 2: the replay gave success" in p.stderr and "the video stops there" in p.stderr
    with Image.open(tmp_path / "gifs" / f"{ep.name}.gif") as gif:
        assert gif.n_frames == 2  # the start and the first action: it stops at the edited one


def test_viewer_shows_final_state_walk_map_and_video(run_dir):
    p = subprocess.run([sys.executable, "-m", "eb_core", "show", str(run_dir)], capture_output=True, text=True,
                       timeout=300)
    assert p.returncode == 0, p.stderr
    ep = sorted((run_dir / "episodes").iterdir())[1]  # the untampered one
    page = (ep / "index.html").read_text()
    finals = list(ep.glob("final_*.png"))
    assert len(finals) == 1 and f"src='{finals[0].name}'" in page and "How it ended" in page
    assert "The walk seen from above" in page and "<polyline" in page and "Distance to the target" in page
    assert "<video controls" in page and "src='episode.mp4'" in page
