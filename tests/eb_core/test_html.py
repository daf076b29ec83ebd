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
    assert '<script>alert' not in ep and "<img src=x" not in ep  # the viewer's own scripts are the only ones
    assert "&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt;" in ep
    assert "&lt;b&gt;go&lt;/b&gt;" in ep
    assert "Output error: the answer contains no JSON object" in ep
    assert "<img src='step001_top.png'" in ep and (tmp_path / "episodes" / "near-0" / "step001_top.png").exists()


def test_index_shows_intervals_and_repeats(tmp_path):
    run(make_config(runner__repeats=2, subset="far"), tmp_path, plugins=[fixture_plugin])
    page = write_html(tmp_path).read_text()
    assert "2 repeats per task" in page and "success rate 100.0% (95% CI" in page
    assert "100.0 <span class=muted>[56.6, 100.0]</span>" in page  # Wilson over the 5 far tasks
    assert "href='episodes/far-0_repeat1/index.html'" in page and "far-0 (repeat 1)" in page
    assert (tmp_path / "episodes" / "far-0_repeat1" / "index.html").exists()


def test_a_run_stopped_before_its_end_is_shown_from_its_episodes(tmp_path):
    run(make_config(limit=3), tmp_path, plugins=[fixture_plugin])
    (tmp_path / "summary.json").unlink()  # as after a kill -9
    page = write_html(tmp_path).read_text()
    assert "Incomplete run" in page and "computed from the 3 episode(s)" in page
    assert "<h1>corridor / scripted-oracle / none</h1>" in page and "?" not in page.split("<h2>")[0]
    assert "success rate 100.0%" in page
    (tmp_path / "episodes.jsonl").write_text("")  # stopped before the first episode finished
    page = write_html(tmp_path).read_text()
    assert "no measured episode yet" in page and "0.0%" not in page.split("<h2>")[0].split("output-error")[0]


def test_language_only_marks_the_image_as_not_sent(tmp_path):
    run(make_config(limit=1, planner__language_only=True), tmp_path / "blind", plugins=[fixture_plugin])
    write_html(tmp_path / "blind")
    ep = (tmp_path / "blind" / "episodes" / "near-0" / "index.html").read_text()
    assert "NOT SENT TO THE MODEL" in ep and "planner.language_only: the model was sent no image" in ep
    assert "alt='the scene (not sent to the model) at step 1'" in ep
    run(make_config(limit=1), tmp_path / "seeing", plugins=[fixture_plugin])
    write_html(tmp_path / "seeing")
    ep = (tmp_path / "seeing" / "episodes" / "near-0" / "index.html").read_text()
    assert "NOT SENT" not in ep and "The model was sent the image below." in ep
    # a step that lists what was in the request is taken at its word
    steps = tmp_path / "seeing" / "episodes" / "near-0" / "steps.jsonl"
    rows = [json.loads(x) for x in steps.read_text().splitlines()]
    rows[0]["sent_images"] = []
    steps.write_text("".join(json.dumps(r) + "\n" for r in rows))
    write_html(tmp_path / "seeing")
    ep = (tmp_path / "seeing" / "episodes" / "near-0" / "index.html").read_text()
    assert "NOT SENT TO THE MODEL" in ep and "sent no image at this step" in ep
