"""The viewer shows a world's ``EnvSpec.notes`` on its episode pages, and its pages keep their structure."""

import re

import fixture_plugin
from eb_core_testutil import make_config

from eb_core import EnvSpec, hookimpl
from eb_core.html import write_compare, write_html
from eb_core.plugins import Registry, get_plugin_manager
from eb_core.runner import run

NOTE = 'Cells are numbered from 0 <b>left</b> & "right" is up.'
NOTE_HTML = "Cells are numbered from 0 &lt;b&gt;left&lt;/b&gt; &amp; &quot;right&quot; is up."


class CorridorWithNotes:
    """A second fixture plugin: the corridor world again, now with a note for readers."""

    @hookimpl
    def eb_register_envs(self):
        return [EnvSpec(name="corridor", entry_point="fixture_plugin:CorridorEnv", notes=NOTE)]


def _registry(plugin, monkeypatch):
    monkeypatch.delenv("EB_PLUGINS", raising=False)  # only ``plugin`` provides 'corridor'
    return Registry(get_plugin_manager(load_entrypoints=False, plugins=[plugin]))


def _pages(root):
    return {p.relative_to(root).as_posix(): p.read_text() for p in sorted(root.rglob("*.html"))}


def test_episode_pages_show_the_worlds_note_escaped(tmp_path, monkeypatch):
    run(make_config(limit=3), tmp_path, plugins=[fixture_plugin])
    monkeypatch.delenv("EB_PLUGINS", raising=False)
    write_html(tmp_path)  # no installed plugin provides 'corridor': the pages are written without a note
    plain = _pages(tmp_path)
    assert len(plain) == 4 and not any("About this world" in page for page in plain.values())
    write_html(tmp_path, registry=_registry(CorridorWithNotes(), monkeypatch))
    noted = _pages(tmp_path)
    assert noted["index.html"] == plain["index.html"]  # the run's index is unchanged
    episodes = [name for name in noted if name.startswith("episodes/")]
    assert len(episodes) == 3
    for name in episodes:
        page = noted[name]
        assert NOTE not in page and page.count(NOTE_HTML) == 1
        para = re.search(r"<p style='[^']*'><b>About this world:</b> [^<]*</p>\n", page).group(0)
        assert page.replace(para, "") == plain[name]  # the note is the only change
        assert page.index("<b>Instruction:</b>") < page.index(para) < page.index("Planner step 1")


def test_a_world_without_notes_shows_none(tmp_path, monkeypatch):
    run(make_config(limit=1), tmp_path, plugins=[fixture_plugin])
    write_html(tmp_path, registry=_registry(fixture_plugin, monkeypatch))  # registered, but its spec has no notes
    assert "About this world" not in (tmp_path / "episodes" / "near-0" / "index.html").read_text()


def test_comparison_pages_show_the_note_too(tmp_path, monkeypatch):
    run(make_config(limit=2), tmp_path / "a", plugins=[fixture_plugin])
    run(make_config(limit=2), tmp_path / "b", plugins=[fixture_plugin])
    write_compare([tmp_path / "a", tmp_path / "b"], tmp_path / "plain")
    noted_registry = _registry(CorridorWithNotes(), monkeypatch)
    write_compare([tmp_path / "a", tmp_path / "b"], tmp_path / "noted", registry=noted_registry)
    plain, noted = _pages(tmp_path / "plain"), _pages(tmp_path / "noted")
    assert sorted(plain) == sorted(noted) == ["index.html", "tasks/near-0.html", "tasks/near-1.html"]
    assert noted["index.html"] == plain["index.html"]
    for name in ("tasks/near-0.html", "tasks/near-1.html"):
        assert "About this world" not in plain[name] and noted[name].count(NOTE_HTML) == 1


def test_episode_page_structure(tmp_path):
    """The parts of an episode page, in order: back link, title, instruction, counts, then each planner step
    (what was sent, the image, labels, reasoning, plan, actions, answer, prompt), then how it ended."""
    run(make_config(limit=1), tmp_path, plugins=[fixture_plugin])
    write_html(tmp_path)
    page = (tmp_path / "episodes" / "near-0" / "index.html").read_text()
    body = page.split("<body>", 1)[1]
    assert body.startswith("<p><a href='../../index.html'>&larr; corridor / scripted-oracle / none</a></p>\n"
                           "<h1>near-0 <span class=muted>(near)</span> <span class=ok>success</span></h1>\n"
                           "<p><b>Instruction:</b> walk to cell 2</p>\n<p class=muted>end: success · env steps ")
    steps = body.split("<div class=step>")[1:]
    assert len(steps) >= 1 and "<h2>How it ended</h2>" in steps[-1] and "</div></div>\n<h2>How it ended" in body
    for n, step in enumerate(steps, start=1):
        order = ["The model was sent 1 image(s): the top view.", f"<img src='step{n:03d}_top.png'",
                 f"<b>Planner step {n}</b>", "<b>Reasoning:</b>", "<b>Plan:</b>",
                 "<th>step</th><th>action</th><th>result</th><th>feedback</th>",
                 "<summary>raw model answer</summary>", "<summary>prompt</summary>"]
        at = [step.index(x) for x in order]
        assert at == sorted(at)
    assert body.endswith("</body></html>\n") and body.count("<script>") == 1  # only the image check
