"""``eb show --bundle``: a static site of three runs whose every link works in headless Chromium."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path
from urllib.parse import unquote, urlparse

import pytest

BROWSER = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")


def _run(tmp_path: Path, name: str, *args: str) -> Path:
    d = tmp_path / name
    p = subprocess.run([sys.executable, "-m", "eb_core", "run", "runner.quiet=true", f"hydra.run.dir={d}", *args],
                       capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr[-2000:]
    return d


def _dom(url: str) -> str:
    p = subprocess.run([BROWSER, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                        "--no-first-run", "--dump-dom", url], capture_output=True, text=True, timeout=120)
    return p.stdout


@pytest.fixture(scope="module")
def bundle(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("bundle")
    runs = [_run(tmp, "nav-oracle", "env=navigation", "model=oracle", "limit=3"),
            _run(tmp, "nav-random", "env=navigation", "model=random", "limit=3"),
            _run(tmp, "hab-oracle", "env=habitat", "model=oracle", "limit=2")]
    out = tmp / "site"
    p = subprocess.run([sys.executable, "-m", "eb_core", "show", "--bundle", str(out), *map(str, runs)],
                       capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr[-2000:]
    return out, runs


def test_leaderboards_capabilities_and_marks(bundle):
    out, runs = bundle
    index = (out / "index.html").read_text()
    assert "<h2 id='navigation'>" in index and "<h2 id='habitat'>" in index
    assert index.count("partial</span>") == 3  # every run played a few tasks of 300
    assert "compare/navigation/index.html" in index
    assert "3 of 300" in index and "2 of 300" in index
    caps = (out / "capabilities.html").read_text()
    assert "<h2>base</h2>" in caps
    meta = json.loads((out / "runs.json").read_text())
    assert [m["world"] for m in meta] == ["navigation", "navigation", "habitat"] and all(m["partial"] for m in meta)
    # self-contained: no absolute link or reference outside the folder
    for page in out.rglob("*.html"):
        text = page.read_text()
        for ref in re.findall(r"(?:href|src)='([^']+)'", text) + re.findall(r'(?:href|src)="([^"]+)"', text):
            assert not ref.startswith(("/", "http:", "https:", "file:")), (page, ref)
    again = subprocess.run([sys.executable, "-m", "eb_core", "show", "--bundle", str(out), str(runs[0])],
                           capture_output=True, text=True, timeout=300)
    assert again.returncode != 0 and "not empty" in again.stderr


@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed (apt-get install -y chromium)")
def test_every_link_opens_in_headless_chromium(bundle):
    out, _ = bundle
    start = (out / "index.html").resolve().as_uri()
    seen: set[str] = set()
    queue = [start]
    pages = 0
    while queue and pages < 40:
        url = queue.pop(0)
        if url in seen:
            continue
        seen.add(url)
        path = Path(unquote(urlparse(url).path))
        assert path.is_file(), f"broken link to {path}"
        dom = _dom(url)
        pages += 1
        assert "<body" in dom, url
        assert 'data-broken="1"' not in dom, f"an image did not load on {url}"
        for href in re.findall(r'<a [^>]*href="([^"#?]+)', dom):
            target = (path.parent / unquote(href)).resolve()
            assert target.is_file(), f"{url}: link {href} goes nowhere"
            if target.suffix == ".html":
                queue.append(target.as_uri())
    names = {Path(unquote(urlparse(u).path)).relative_to(out.resolve()).as_posix() for u in seen}
    assert "capabilities.html" in names and "compare/navigation/index.html" in names
    assert any(n.startswith("runs/") and n.count("/") >= 3 for n in names)  # an episode page was reached


def test_runs_are_verified_and_a_tampered_run_is_marked(bundle, tmp_path):
    out, runs = bundle
    meta = json.loads((out / "runs.json").read_text())
    assert all(m["verified"] is True for m in meta), meta
    bad = tmp_path / "tampered"
    shutil.copytree(runs[0], bad)
    lines = (bad / "episodes.jsonl").read_text().splitlines()
    first = json.loads(lines[0])
    first["success"] = not first["success"]
    (bad / "episodes.jsonl").write_text("\n".join([json.dumps(first), *lines[1:]]) + "\n")
    site = tmp_path / "site"
    p = subprocess.run([sys.executable, "-m", "eb_core", "show", "--bundle", str(site), str(bad)],
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    entry = json.loads((site / "runs.json").read_text())[0]
    assert entry["verified"] is False and "success" in entry["verify"]
    assert "<span class=bad" in (site / "index.html").read_text()
