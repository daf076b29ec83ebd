"""GL backend selection: a preset MUJOCO_GL is respected, a missing backend fails with the apt-get fix."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from eb_scenekit.gl import EGL_FIX, OSMESA_FIX, RenderBackendError, select_gl_backend


def _env_without_gl(**extra: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "PYOPENGL_PLATFORM")}
    env.update(extra)
    return env


def test_preset_backend_is_respected(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MUJOCO_GL", "osmesa")
    monkeypatch.setenv("EB_SCENEKIT_FORCE_NO_GL", "1")  # a preset value is never probed
    assert select_gl_backend() == "osmesa"


def test_unset_backend_is_probed_and_exported() -> None:
    code = "import os; from eb_scenekit.gl import select_gl_backend as s; b = s(); print(b, os.environ['MUJOCO_GL'])"
    out = subprocess.run([sys.executable, "-c", code], env=_env_without_gl(), capture_output=True, text=True,
                         timeout=60)
    assert out.returncode == 0, out.stderr
    backend, exported = out.stdout.split()
    assert backend == exported and backend in ("egl", "osmesa")


def test_no_backend_raises_with_the_fix(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("MUJOCO_GL", raising=False)
    monkeypatch.setenv("EB_SCENEKIT_FORCE_NO_GL", "1")
    with pytest.raises(RenderBackendError) as err:
        select_gl_backend()
    msg = str(err.value)
    assert "\n" not in msg
    assert EGL_FIX in msg and OSMESA_FIX in msg
    assert isinstance(err.value, RuntimeError)


def test_importing_the_renderer_without_gl_fails_clearly() -> None:
    code = "import eb_scenekit.render"
    out = subprocess.run([sys.executable, "-c", code], env=_env_without_gl(EB_SCENEKIT_FORCE_NO_GL="1"),
                         capture_output=True, text=True, timeout=60)
    assert out.returncode != 0
    last = out.stderr.strip().splitlines()[-1]
    assert last.startswith("eb_scenekit.gl.RenderBackendError")
    assert "apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri" in last
    assert "apt-get install libosmesa6" in last


def test_catalogue_and_layouts_do_not_import_mujoco() -> None:
    code = ("import sys, eb_scenekit; eb_scenekit.generate_room('bathroom', 0).xml; "
            "print('mujoco' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], env=_env_without_gl(EB_SCENEKIT_FORCE_NO_GL="1"),
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "False"


def test_import_mujoco_chooses_the_backend_first() -> None:
    code = ("import os, sys; from eb_scenekit.gl import import_mujoco; m = import_mujoco(); "
            "print(m is sys.modules['mujoco'], os.environ['MUJOCO_GL'])")
    out = subprocess.run([sys.executable, "-c", code], env=_env_without_gl(), capture_output=True, text=True,
                         timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split()[0] == "True" and out.stdout.split()[1] in ("egl", "osmesa")
    code = "import sys\ntry:\n  from eb_scenekit.gl import import_mujoco; import_mujoco()\nexcept Exception as e:\n" \
           "  print(type(e).__name__, 'mujoco' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], env=_env_without_gl(EB_SCENEKIT_FORCE_NO_GL="1"),
                         capture_output=True, text=True, timeout=60)
    assert out.stdout.strip() == "RenderBackendError False", out.stderr
