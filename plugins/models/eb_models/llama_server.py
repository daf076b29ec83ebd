"""``python -m eb_models.llama_server ARGS``: llama-cpp-python's OpenAI-compatible server
(``python -m llama_cpp.server ARGS``, same arguments), safe on a llama.cpp built with AMX kernels.

A llama.cpp compiled for the build machine's own CPU includes AMX kernels on Xeons that have AMX, and they
segfault on the first real request (see :mod:`eb_models.llamacpp_backend`). With such a build this entry point
loads the models without llama.cpp's extra CPU buffer types, and says so in one line on stderr; with any other
build it is exactly llama-cpp-python's server.
"""

from __future__ import annotations

import sys


def main() -> None:
    try:
        import llama_cpp  # noqa: F401
        from llama_cpp.server.__main__ import main as server_main
    except ModuleNotFoundError as exc:
        from eb_models.plugin import LLAMACPP_INSTALL

        sys.exit(f"eb_models.llama_server needs llama-cpp-python[server] ({exc.name} is missing): {LLAMACPP_INSTALL}")
    from eb_models.llamacpp_backend import build_has_amx, without_extra_buffers

    if build_has_amx():
        print("eb_models.llama_server: this llama.cpp build has AMX kernels; loading models without llama.cpp's "
              "extra CPU buffers (use_extra_bufts=false)", file=sys.stderr, flush=True)
        with without_extra_buffers():
            server_main()
    else:
        server_main()


if __name__ == "__main__":
    main()
