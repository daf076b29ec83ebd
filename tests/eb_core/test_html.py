"""`eb show`: the HTML viewer escapes every piece of model text and links every episode."""

import json

import fixture_plugin
from eb_core_testutil import make_config
from eb_core.html import write_html
from eb_core.runner import run

EVIL = '<script>alert("x")</script><img src=x onerror=alert(1)>'


def test_viewer_escapes_model_text_and_links_episodes(tmp_path):
    answers = [EVIL, json.dumps({"reasoning_and_reflection": EVIL, "language_plan": "<b>go</b>",
                                 "executable_plan": [{"action_id": 1}, {"action_id": 1}]})]
    cfg = make_config(model={"name": "evil", "backend": "scripted", "answers": answers}, limit=2)
    run(cfg, tmp_path, plugins=[fixture_plugin])
    index = write_html(tmp_path)
    page = index.read_text()
    assert "near-0" in page and "href='episodes/near-0/index.html'" in page
    ep = (tmp_path / "episodes" / "near-0" / "index.html").read_text()
    assert "<script>" not in ep and "<img src=x" not in ep
    assert "&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt;" in ep
    assert "&lt;b&gt;go&lt;/b&gt;" in ep
    assert "Output error: the answer contains no JSON object" in ep
    assert "<img src='step001_top.png'" in ep and (tmp_path / "episodes" / "near-0" / "step001_top.png").exists()
