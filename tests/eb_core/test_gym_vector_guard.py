"""A script that builds a vector env without the ``__main__`` guard gets one line that names the guard."""

from __future__ import annotations

import subprocess
import sys
import textwrap


def test_missing_main_guard_is_named(tmp_path):
    script = tmp_path / "train.py"
    script.write_text(textwrap.dedent("""
        from eb_core.gym import make_vector_env
        envs = make_vector_env("corridor", 2, workers=1)
        print("built", envs.num_envs)
        envs.close()
    """))
    p = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert p.returncode != 0 and "built" not in p.stdout
    last = p.stderr.strip().splitlines()[-1]
    assert 'if __name__ == "__main__":' in last and "could not be started" in last
    assert len(p.stderr.splitlines()) < 40, p.stderr


def test_the_same_script_with_the_guard_runs(tmp_path):
    script = tmp_path / "train.py"
    script.write_text(textwrap.dedent("""
        from eb_core.gym import make_vector_env
        if __name__ == "__main__":
            envs = make_vector_env("corridor", 2, workers=1)
            print("built", envs.num_envs)
            envs.close()
    """))
    p = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert p.returncode == 0, p.stderr[-1500:]
    assert "built 2" in p.stdout
