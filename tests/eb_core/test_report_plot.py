"""`eb report` with several runs in every format, ablation deltas, the error breakdown and `--plot`."""

import csv
import io
import json
import struct

import pytest

import fixture_plugin
from eb_core_testutil import make_config
from eb_core.cli import main
from eb_core.report import render_report
from eb_core.runner import run

LEFT = json.dumps({"visual_state_description": "the goal", "executable_plan": [{"action_id": 0}]})


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("runs")
    run(make_config(), root / "oracle", plugins=[fixture_plugin])
    run(make_config(model={"name": "lefty", "backend": "scripted", "answers": [LEFT, "no json"]}),
        root / "lefty", plugins=[fixture_plugin])
    run(make_config(ablation={"name": "blind"}, planner__language_only=True), root / "oracle_blind",
        plugins=[fixture_plugin])
    return root


def test_two_runs_in_every_format(runs, tmp_path):
    dirs = [str(runs / "oracle"), str(runs / "lefty")]
    md = render_report(dirs, "markdown", str(tmp_path / "r.md"))
    assert "| corridor | scripted-oracle | none | 100.0 | 100.0 [72.2, 100.0] |" in md
    assert "| corridor | lefty | none | 0.0 | 0.0 [0.0, 27.8] |" in md
    assert "Automatic error analysis, all subsets" in md and "format error" in md and "repetition / loop" in md
    rows = list(csv.DictReader(io.StringIO(render_report(dirs, "csv", str(tmp_path / "r.csv")))))
    assert [r["model"] for r in rows] == ["scripted-oracle", "lefty"]
    assert rows[1]["errors:format_error"] != "0" and float(rows[1]["errors:format_error:episode_rate"]) == 100.0
    assert rows[0]["errors:format_error"] == "0"
    tex = render_report(dirs, "latex", str(tmp_path / "r.tex"))
    assert tex.count("\\begin{tabular}") >= 4 and "100.0 [72.2, 100.0]" in tex and "95\\% CI" in tex
    assert "\\\\" in tex and "% needs \\usepackage{booktabs}" in tex
    page = render_report(dirs, "html", str(tmp_path / "r.html"))
    assert page.startswith("<!doctype html>") and "<td>lefty</td>" in page and "Automatic error analysis" in page
    rich = render_report(dirs, "rich", str(tmp_path / "r.txt"))
    assert "Success rate (%)" in rich and "lefty" in rich


def test_ablation_deltas_against_the_baseline_run(runs, tmp_path):
    md = render_report([str(runs / "oracle"), str(runs / "oracle_blind")], "markdown", str(tmp_path / "a.md"))
    assert "Ablation deltas — corridor / scripted-oracle" in md
    assert "| corridor | scripted-oracle | blind | none |" in md


def test_report_errors_relabels_an_old_run_per_subset(runs, tmp_path, capsys):
    import shutil

    old = tmp_path / "old"
    shutil.copytree(runs / "lefty", old)
    lines = [json.loads(x) for x in (old / "episodes.jsonl").read_text().splitlines()]
    for rec in lines:  # as written before the labeller existed
        rec.pop("error_counts"), rec.pop("perception_score")
    (old / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in lines))
    md = render_report([str(old)], "markdown", str(tmp_path / "o.md"))
    assert "format error" in md  # labelled from the step files on the way in
    assert main(["report", str(old), "--errors", "--format", "markdown"]) == 0
    out = capsys.readouterr().out
    assert "Automatic error analysis, subset near" in out and "Automatic error analysis, subset far" in out


def test_plot_writes_a_png_with_both_charts(runs, tmp_path, capsys):
    png = tmp_path / "plot.png"
    assert main(["report", str(runs / "oracle"), str(runs / "lefty"), "--plot", str(png), "--format", "csv",
                 "--out", str(tmp_path / "t.csv")]) == 0
    head = png.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", head[16:24])
    assert width > 1200 and 400 < height < 900  # two panels side by side
    svg = tmp_path / "plot.svg"
    assert main(["report", str(runs / "oracle"), "--plot", str(svg), "--out", str(tmp_path / "u.md")]) == 0
    assert "<svg" in svg.read_text()[:500]


def test_bad_report_options_fail_in_one_line(runs, capsys):
    assert main(["report", str(runs / "oracle"), "--format", "pdf"]) == 2
    assert "use rich, markdown, csv, latex or html" in capsys.readouterr().err
    assert main(["report", str(runs / "oracle"), "--plot", "x.pdf"]) == 2
    err = capsys.readouterr().err
    assert "must end in .png or .svg" in err and err.count("\n") == 1
