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
    assert "success rate 100.0%" in page and "output-error rate 0.0%" in page
    (tmp_path / "episodes.jsonl").write_text("")  # stopped before the first episode finished
    page = write_html(tmp_path).read_text()
    head = page.split("<h2>")[0]
    assert "no measured episode yet" in head and "output-error rate -" in head and "0.0%" not in head


def test_language_only_marks_the_image_as_not_sent(tmp_path):
    run(make_config(limit=1, planner__language_only=True), tmp_path / "blind", plugins=[fixture_plugin])
    steps = tmp_path / "blind" / "episodes" / "near-0" / "steps.jsonl"
    assert all(json.loads(x)["sent_images"] == [] for x in steps.read_text().splitlines())  # recorded per step
    write_html(tmp_path / "blind")
    ep = (tmp_path / "blind" / "episodes" / "near-0" / "index.html").read_text()
    assert "NOT SENT TO THE MODEL" in ep and "The model was sent no image at this step (text only)." in ep
    assert "alt='the scene (not sent to the model) at step 1'" in ep
    # older step files without sent_images are read with the run's config
    rows = [json.loads(x) for x in steps.read_text().splitlines()]
    steps.write_text("".join(json.dumps({k: v for k, v in r.items() if k != "sent_images"}) + "\n" for r in rows))
    write_html(tmp_path / "blind")
    ep = (tmp_path / "blind" / "episodes" / "near-0" / "index.html").read_text()
    assert "NOT SENT TO THE MODEL" in ep and "planner.language_only: the model was sent no image" in ep
    run(make_config(limit=1), tmp_path / "seeing", plugins=[fixture_plugin])
    write_html(tmp_path / "seeing")
    ep = (tmp_path / "seeing" / "episodes" / "near-0" / "index.html").read_text()
    assert "NOT SENT" not in ep and "The model was sent 1 image(s): the top view." in ep


def test_the_viewer_names_the_frames_and_views_that_were_sent(tmp_path):
    one_step = json.dumps({"reasoning_and_reflection": "r", "executable_plan": [{"action_id": 1}]})
    model = {"name": "one-step", "backend": "scripted", "answers": [one_step] * 4}
    run(make_config(limit=1, planner__multi_step_images=3, model=model), tmp_path / "frames",
        plugins=[fixture_plugin])
    steps = [json.loads(x) for x in
             (tmp_path / "frames" / "episodes" / "near-0" / "steps.jsonl").read_text().splitlines()]
    assert steps[0]["sent_images"] == ["frame-0"]  # just after reset there is one frame
    assert len(steps) >= 2 and steps[1]["sent_images"][-1] == f"frame-{len(steps[1]['sent_images']) - 1}"
    write_html(tmp_path / "frames")
    ep = (tmp_path / "frames" / "episodes" / "near-0" / "index.html").read_text()
    n = len(steps[1]["sent_images"])
    assert n > 1 and f"The model was sent {n} image(s): the last {n} frames of its view, oldest first" in ep
    assert "The model was sent 1 image(s): its current view (no earlier frame yet)." in ep
    run(make_config(limit=1, env__multi_view=True), tmp_path / "views", plugins=[fixture_plugin])
    steps = [json.loads(x) for x in
             (tmp_path / "views" / "episodes" / "near-0" / "steps.jsonl").read_text().splitlines()]
    assert steps[0]["sent_images"] == ["top", "side"]
    write_html(tmp_path / "views")
    ep = (tmp_path / "views" / "episodes" / "near-0" / "index.html").read_text()
    assert "The model was sent 2 image(s): the top view and the side view (in this order, as below)." in ep


def _two_runs(tmp_path):
    evil = json.dumps({"visual_state_description": EVIL, "reasoning_and_reflection": EVIL,
                       "executable_plan": [{"action_id": 0}]})
    run(make_config(limit=2), tmp_path / "oracle", plugins=[fixture_plugin])
    run(make_config(model={"name": "evil", "backend": "scripted", "answers": [evil]}, limit=2), tmp_path / "evil",
        plugins=[fixture_plugin])
    return [str(tmp_path / "oracle"), str(tmp_path / "evil")]


def test_steps_show_their_error_labels_and_the_index_filters(tmp_path):
    dirs = _two_runs(tmp_path)
    page = write_html(dirs[1]).read_text()
    assert "<h2>Automatic error analysis</h2>" in page and "data-filter='errors'" in page
    assert "<option value='failed_action'>failed action (unclassified)</option>" in page
    assert "data-result='fail' data-errors='failed_action repetition'" in page
    ep = (tmp_path / "evil" / "episodes" / "near-0" / "index.html").read_text()
    assert "class='lab planning'" in ep and "failed action (unclassified)</span>" in ep


def test_comparison_folder_puts_runs_side_by_side(tmp_path):
    from eb_core.cli import main

    dirs = _two_runs(tmp_path)
    out = tmp_path / "cmp"
    assert main(["show", *dirs, "--out", str(out)]) == 0
    index = (out / "index.html").read_text()
    assert "scripted-oracle / none vs evil / none" in index and "href='tasks/near-0.html'" in index
    assert "data-result='they differ'" in index
    task = (out / "tasks" / "near-0.html").read_text()
    assert '<script>alert' not in task and "&lt;script&gt;alert(&quot;x&quot;)" in task
    assert "<img src='../img/0/near-0/step001_top.png'" in task and "<img src='../img/1/near-0/step001_top.png'" in task
    assert (out / "img" / "1" / "near-0" / "step001_top.png").exists()
    assert task.count("<h2>Planner step") >= 2


def test_comparison_page_in_headless_chromium(tmp_path):
    import shutil
    import subprocess

    browser = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")
    if browser is None:
        import pytest

        pytest.skip("no Chromium installed (apt-get install -y chromium)")
    from eb_core.html import write_compare

    index = write_compare(_two_runs(tmp_path), tmp_path / "cmp")
    page = index.parent / "tasks" / "near-0.html"
    dom = subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--dump-dom", page.as_uri()],
                         capture_output=True, text=True, timeout=120).stdout
    imgs = [tag for tag in dom.split("<img")[1:]]
    assert len(imgs) >= 4 and all("data-loaded=\"1\"" in t.split(">")[0] for t in imgs)  # every image loaded
    assert "data-broken=\"1\"" not in dom
    assert "<script>alert" not in dom and "onerror=alert" not in dom.replace("&lt;img src=x onerror=alert", "")
    assert "&lt;script&gt;alert(\"x\")&lt;/script&gt;" in dom  # shown as text


def test_index_filters_work_in_headless_chromium(tmp_path):
    import shutil
    import subprocess

    browser = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")
    if browser is None:
        import pytest

        pytest.skip("no Chromium installed (apt-get install -y chromium)")
    from eb_core.html import write_compare

    index = write_compare(_two_runs(tmp_path), tmp_path / "cmp")

    def visible_rows(query):
        dom = subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--dump-dom",
                              index.as_uri() + query], capture_output=True, text=True, timeout=120).stdout
        rows = dom.split("<tr data-row")[1:]
        return sum(1 for r in rows if "display: none" not in r.split(">")[0]), len(rows)

    assert visible_rows("") == (2, 2)
    assert visible_rows("?result=they%20differ") == (2, 2)  # the oracle succeeds where the evil model fails
    assert visible_rows("?result=all%20succeeded") == (0, 2)
    assert visible_rows("?errors=failed_action&subset=near") == (2, 2)
