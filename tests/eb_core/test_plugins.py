"""Plugin manager and registry: discovery, duplicates, unknown names, lazy loading, hook docs."""

import inspect
import subprocess
import sys
import types
from pathlib import Path

import pytest

import fixture_plugin
from eb_core import hookimpl, hookspecs
from eb_core.plugins import PluginError, Registry, get_plugin_manager, plugin_versions
from eb_core.specs import EnvSpec, MissingDependencyError, ModelBackendSpec, load_entry_point

TESTS = Path(__file__).parents[1]


def _plugin(name, **hooks):
    mod = types.ModuleType(name)
    for hook_name, fn in hooks.items():
        setattr(mod, hook_name, hookimpl(fn))
    return mod


def test_fresh_manager_each_time():
    assert get_plugin_manager() is not get_plugin_manager()


def test_builtins_register_through_hooks(registry):
    assert registry.planners["vlm"].plugin == "eb_core"
    assert {"success_rate", "subgoal_success", "steps", "errors", "usage"} <= set(registry.metrics)
    assert registry.augmenters["detection_boxes"].plugin == "eb_core"
    assert registry.envs["corridor"].plugin == "fixture_plugin"


def test_duplicate_names_fail_naming_both_plugins():
    twin = _plugin("twin_plugin", eb_register_envs=lambda: [EnvSpec(name="corridor", entry_point="x.y:Z")])
    with pytest.raises(PluginError, match=r"env 'corridor' is registered twice: by plugin 'fixture_plugin' and by plugin 'twin_plugin'"):
        Registry(get_plugin_manager(plugins=[fixture_plugin, twin]))


def test_misspelled_hook_fails_at_start_up():
    bad = _plugin("typo_plugin", eb_register_env=lambda: [])
    with pytest.raises(PluginError, match="unknown hook"):
        get_plugin_manager(plugins=[bad])


def test_wrong_return_type_is_named():
    bad = _plugin("bad_plugin", eb_register_model_backends=lambda: [EnvSpec(name="x", entry_point="a.b:C")])
    with pytest.raises(PluginError, match="bad_plugin.*returned EnvSpec, expected ModelBackendSpec"):
        Registry(get_plugin_manager(plugins=[bad]))


def test_unknown_name_lists_what_exists(registry):
    with pytest.raises(PluginError, match=r"unknown env 'kitchen'; available: corridor. Is the plugin"):
        registry.get("env", "kitchen")


def test_entry_points_are_strings_checked_and_loaded_lazily():
    with pytest.raises(ValueError, match="package.module:Attr"):
        EnvSpec(name="x", entry_point="no_colon_here")
    with pytest.raises(MissingDependencyError, match=r"Fix: pip install eb-fancy"):
        ModelBackendSpec(name="f", entry_point="eb_fancy_missing.mod:X", install_hint="pip install eb-fancy").load()
    assert load_entry_point("fixture_plugin:CorridorEnv") is fixture_plugin.CorridorEnv


def test_eb_plugins_env_var_registers_modules(monkeypatch):
    monkeypatch.setenv("EB_PLUGINS", "fixture_plugin")
    assert "corridor" in Registry.create().envs
    monkeypatch.setenv("EB_PLUGINS", "no_such_module_xyz")
    with pytest.raises(PluginError, match="EB_PLUGINS names 'no_such_module_xyz'"):
        get_plugin_manager()


def test_plugin_versions_are_recorded(registry):
    versions = plugin_versions(registry.pm)
    assert versions["eb_core"].startswith("embodiedbench ")
    assert "fixture_plugin" in versions


def test_lifecycle_hooks_observe_a_run(tmp_path):
    from eb_core_testutil import make_config
    from eb_core.runner import run

    seen = []

    class Observer:
        @hookimpl
        def eb_on_run_start(self, event):
            seen.append(("run_start", event.n_pending))

        @hookimpl
        def eb_on_episode_start(self, event):
            seen.append(("episode_start", event.task_id))

        @hookimpl
        def eb_on_step_end(self, event):
            seen.append(("step_end", event.task_id, event.env_step))

        @hookimpl
        def eb_on_episode_end(self, event):
            seen.append(("episode_end", event.record["task_id"], event.record["success"]))
            event.record["success"] = False  # observers cannot change results: it is a copy

        @hookimpl
        def eb_on_run_end(self, event):
            seen.append(("run_end", event.summary["overall"]["success_rate"]))

    pm = get_plugin_manager(plugins=[fixture_plugin])
    pm.register(Observer(), name="observer")
    summary = run(make_config(limit=1), tmp_path, registry=Registry(pm))
    assert seen[0] == ("run_start", 1)
    assert ("episode_start", "near-0") in seen and ("step_end", "near-0", 2) in seen
    assert ("episode_end", "near-0", True) in seen and seen[-1] == ("run_end", 1.0)
    assert summary["overall"]["success_rate"] == 1.0
    with pytest.raises(Exception):
        from eb_core.events import RunEndEvent

        RunEndEvent(run_dir="x", summary={}).run_dir = "y"  # frozen


def test_every_hook_is_prefixed_documented_and_tested():
    """The datasette meta-test: a hook nobody documents or tests is a hook nobody can rely on."""
    tests_text = "\n".join(p.read_text() for p in TESTS.rglob("test_*.py"))
    hooks = [name for name, fn in inspect.getmembers(hookspecs, inspect.isfunction) if hasattr(fn, "eb_spec")]
    assert len(hooks) >= 11
    for name in hooks:
        fn = getattr(hookspecs, name)
        assert name.startswith("eb_"), name
        assert fn.__doc__ and len(fn.__doc__.strip()) > 30, f"{name} needs a docstring"
        assert name in tests_text, f"hook {name} has no test"


def test_eb_list_imports_no_simulator_or_model_sdk():
    code = ("import sys; from eb_core.cli import main; main(['list']); "
            "bad = [m for m in ('mujoco', 'litellm', 'openai', 'anthropic', 'torch') if m in sys.modules]; "
            "print('HEAVY', bad)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "HEAVY []" in out.stdout


def test_eb_config_searchpath_and_register_hooks_of_the_fixture(registry):
    # eb_register_envs / eb_register_model_backends / eb_register_planners / eb_register_augmenters /
    # eb_register_metrics / eb_config_searchpath are exercised here and above.
    assert any(p.startswith("file://") for p in registry.config_searchpath())
    assert registry.model_backends["scripted"].plugin == "fixture_plugin"
