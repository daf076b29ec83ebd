"""Pick an offscreen OpenGL backend for MuJoCo before it is imported.

MuJoCo reads ``MUJOCO_GL`` once, at import time, so the choice has to be made first. We respect a value the
user already set; otherwise we probe EGL, then OSMesa, with ``ctypes`` only (no MuJoCo import, no subprocess),
store the winner in ``os.environ["MUJOCO_GL"]`` (which also caches it for child processes) and return it.

``EB_SCENEKIT_FORCE_NO_GL=1`` is a test-only hook: it makes every probe fail so the error path can be tested.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import importlib.util
import os
from types import ModuleType

__all__ = ["RenderBackendError", "select_gl_backend", "import_mujoco", "EGL_FIX", "OSMESA_FIX"]

EGL_FIX = "apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri"
"""The Debian/Ubuntu command that installs a working EGL (Mesa llvmpipe is enough, no GPU needed)."""

OSMESA_FIX = "apt-get install libosmesa6"
"""The Debian/Ubuntu command that installs OSMesa, the slower pure-software fallback."""

_FORCE_FAIL_ENV = "EB_SCENEKIT_FORCE_NO_GL"


class RenderBackendError(RuntimeError):
    """No offscreen OpenGL backend works on this machine; the message names the package that fixes it."""


def _probe_egl() -> str | None:
    """Return None if an EGL display can be initialised headlessly, else a short reason."""
    if os.environ.get(_FORCE_FAIL_ENV):
        return f"disabled by {_FORCE_FAIL_ENV}"
    if importlib.util.find_spec("OpenGL") is None:
        return "PyOpenGL is not installed (pip install PyOpenGL)"
    try:
        lib = ctypes.CDLL("libEGL.so.1")
    except OSError:
        name = ctypes.util.find_library("EGL")
        if name is None:
            return "libEGL.so.1 not found"
        try:
            lib = ctypes.CDLL(name)
        except OSError as exc:
            return f"cannot load {name}: {exc}"
    vp = ctypes.c_void_p
    lib.eglGetProcAddress.restype = vp
    lib.eglGetProcAddress.argtypes = [ctypes.c_char_p]
    lib.eglInitialize.restype = ctypes.c_uint
    lib.eglInitialize.argtypes = [vp, vp, vp]
    lib.eglTerminate.argtypes = [vp]
    lib.eglGetDisplay.restype = vp
    lib.eglGetDisplay.argtypes = [vp]

    displays: list[int] = []
    query_addr = lib.eglGetProcAddress(b"eglQueryDevicesEXT")
    plat_addr = lib.eglGetProcAddress(b"eglGetPlatformDisplayEXT")
    if query_addr and plat_addr:
        query = ctypes.CFUNCTYPE(ctypes.c_uint, ctypes.c_int, ctypes.POINTER(vp), ctypes.POINTER(ctypes.c_int))(
            query_addr
        )
        get_plat = ctypes.CFUNCTYPE(vp, ctypes.c_uint, vp, vp)(plat_addr)
        devices = (vp * 8)()
        count = ctypes.c_int(0)
        if query(8, devices, ctypes.byref(count)):
            egl_platform_device_ext = 0x313F
            for i in range(count.value):
                dpy = get_plat(egl_platform_device_ext, devices[i], None)
                if dpy:
                    displays.append(dpy)
    default = lib.eglGetDisplay(None)
    if default:
        displays.append(default)
    if not displays:
        return "no EGL display or device found"
    for dpy in displays:
        major, minor = ctypes.c_int(0), ctypes.c_int(0)
        if lib.eglInitialize(dpy, ctypes.byref(major), ctypes.byref(minor)):
            lib.eglTerminate(dpy)
            return None
    return "eglInitialize failed on every display (no Mesa EGL driver?)"


def _probe_osmesa() -> str | None:
    """Return None if libOSMesa can be loaded, else a short reason."""
    if os.environ.get(_FORCE_FAIL_ENV):
        return f"disabled by {_FORCE_FAIL_ENV}"
    if importlib.util.find_spec("OpenGL") is None:
        return "PyOpenGL is not installed (pip install PyOpenGL)"
    for name in ("libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so", ctypes.util.find_library("OSMesa")):
        if not name:
            continue
        try:
            lib = ctypes.CDLL(name)
        except OSError:
            continue
        if hasattr(lib, "OSMesaCreateContextExt"):
            return None
    return "libOSMesa not found"


def select_gl_backend() -> str:
    """Choose the offscreen GL backend MuJoCo will use and export it as ``MUJOCO_GL``.

    Returns:
        The backend name: whatever ``MUJOCO_GL`` was already set to, else ``"egl"`` or ``"osmesa"``.

    Raises:
        RenderBackendError: neither EGL nor OSMesa works; the one-line message says why and what to install.
    """
    preset = os.environ.get("MUJOCO_GL")
    if preset:
        return preset
    egl_reason = _probe_egl()
    if egl_reason is None:
        os.environ["MUJOCO_GL"] = "egl"
        os.environ.setdefault("PYOPENGL_PLATFORM", "egl")
        return "egl"
    osmesa_reason = _probe_osmesa()
    if osmesa_reason is None:
        os.environ["MUJOCO_GL"] = "osmesa"
        os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
        return "osmesa"
    raise RenderBackendError(
        f"No offscreen OpenGL backend for MuJoCo: EGL failed ({egl_reason}), OSMesa failed ({osmesa_reason}). "
        f"Fix: `{EGL_FIX}` (EGL, recommended) or `{OSMESA_FIX}` (OSMesa), or set MUJOCO_GL yourself."
    )


def import_mujoco() -> ModuleType:
    """Choose the backend (:func:`select_gl_backend`), then import MuJoCo and return the module.

    Write ``mujoco = import_mujoco()`` instead of ``import mujoco`` in any module that may be the first of a
    process to import MuJoCo, so the backend is always chosen before MuJoCo reads ``MUJOCO_GL``.
    """
    select_gl_backend()
    import mujoco

    return mujoco
