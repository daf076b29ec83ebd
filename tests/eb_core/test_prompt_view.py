"""`eb prompt`: the request of one planner call, from the same planner and episode code as `eb run`."""

import io
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import fixture_plugin
from eb_core_testutil import make_config
from eb_core.config import ConfigError
from eb_core.plugins import Registry, get_plugin_manager
from eb_core.prompt_view import capture_prompt, render_request

FIXTURE_DIR = Path(__file__).parent


@pytest.fixture(scope="module")
def registry():
    return Registry(get_plugin_manager(load_entrypoints=False, plugins=[fixture_plugin]))


def agent_cell(png: bytes, length=8) -> int:
    img = np.asarray(Image.open(io.BytesIO(png)))
    cell = img.shape[1] // length
    return int(np.argmax([img[0, i * cell, 0] for i in range(length)]))


def test_step_n_is_reached_by_the_expert_and_shows_its_history(registry):
    cfg = make_config()
    req0, _ = capture_prompt(cfg, registry, "far-0", 0)
    req2, note = capture_prompt(cfg, registry, "far-0", 2)
    assert note is None
    assert "Nothing yet" in req0.messages[-1].text
    assert "Step 1: action 1 (step right)" in req2.messages[-1].text and "Step 2: action 1" in req2.messages[-1].text
    assert "Step 3" not in req2.messages[-1].text
    [img] = [p for p in req2.messages[-1].content if hasattr(p, "png")]
    assert agent_cell(img.png) == 2  # far-0 starts at cell 0; two expert steps right


def test_render_writes_prompt_txt_and_each_image(registry, tmp_path):
    cfg = make_config(planner__multi_step_images=3, env__multi_view=True)
    req, _ = capture_prompt(cfg, registry, "far-0", 2)
    text = render_request(req, tmp_path)
    assert (tmp_path / "prompt.txt").read_text() == text
    names = sorted(p.name for p in tmp_path.glob("*.png"))
    assert names == ["image01_frame-0.png", "image02_frame-1.png", "image03_frame-2.png", "image04_side.png"]
    assert [agent_cell((tmp_path / n).read_bytes()) for n in names[:3]] == [0, 1, 2]
    assert text.index("[image 1: frame-0 -> image01_frame-0.png]") < text.index("## Action list")  # images first
    assert (tmp_path / "schema.json").exists()  # the scripted backend takes schemas


def test_a_step_past_the_end_is_one_clear_error(registry):
    # near-0 is two cells from the goal: the expert (one action per call) solves it in calls 1 and 2
    # (capture_prompt counts from 0, the command and its messages from 1, as the viewer does)
    with pytest.raises(ConfigError, match=r"\(success\) after 2 planner calls, before call 6; pick step=1..2"):
        capture_prompt(make_config(), registry, "near-0", 5)
    with pytest.raises(ConfigError, match="unknown task id 'nope'"):
        capture_prompt(make_config(), registry, "nope", 0)


def test_eb_prompt_command(tmp_path):
    env = dict(os.environ, EB_PLUGINS="fixture_plugin", EB_DISABLE_PLUGIN_AUTOLOAD="1", PYTHONPATH=str(FIXTURE_DIR))
    r = subprocess.run([sys.executable, "-m", "eb_core.cli", "prompt", "env=corridor", "model=scripted-oracle",
                        "task=far-1", "step=2", "ablation=language_only", f"out={tmp_path}"],
                       capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 0, r.stderr
    assert "Step 1: action 1 (step right)" in r.stdout and "You are at cell" not in r.stdout
    assert (tmp_path / "prompt.txt").exists() and not list(tmp_path.glob("*.png"))
    bad = subprocess.run([sys.executable, "-m", "eb_core.cli", "prompt", "env=corridor", "step=x", "task=far-1"],
                         capture_output=True, text=True, env=env, timeout=120)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "step must be a whole number" in bad.stderr
    zero = subprocess.run([sys.executable, "-m", "eb_core.cli", "prompt", "env=corridor", "step=0", "task=far-1"],
                          capture_output=True, text=True, env=env, timeout=120)
    assert zero.returncode == 2 and "1 = the first, as the viewer counts" in zero.stderr


def test_the_schema_decision_follows_the_backend_as_eb_run_would():
    """A preset that sets neither structured_output nor supports_json_schema: a backend's class attribute decides;
    a backend whose flag is a per-instance property (LiteLLM) sends the textual format, its documented default."""
    from eb_core.prompt_view import _sends_schema

    class Fixed:
        supports_json_schema = True

    class PerInstance:
        @property
        def supports_json_schema(self) -> bool:
            return True

    assert _sends_schema({"backend": "x"}, Fixed) is True
    assert _sends_schema({"backend": "x"}, PerInstance) is False
    assert _sends_schema({"backend": "x", "supports_json_schema": True}, PerInstance) is True
    assert _sends_schema({"backend": "x", "structured_output": "json_schema"}, PerInstance) is True
    assert _sends_schema({"backend": "x", "structured_output": "none"}, Fixed) is False
