"""What makes scene builds cheap at reset keeps them exact: the contact-free first forward, the compiled-model cache,
the MJCF writer's quoting."""

from __future__ import annotations

from xml.sax.saxutils import quoteattr

import numpy as np

from eb_scenekit import SceneBuilder, SceneRenderer, free_camera
from eb_scenekit import scene as scene_mod
from eb_scenekit._mjcf import quote
from eb_scenekit._mujoco import mujoco
from eb_scenekit.scene import MODEL_CACHE_BYTES, MODEL_CACHE_SIZE, compile_model


def _parked_pair(name: str = "parked") -> SceneBuilder:
    """A studio with a table and two movable apples parked on the same spot (as worlds park hidden objects)."""
    b = SceneBuilder(name=name, offscreen=(64, 64))
    b.add_studio()
    b.add_object("Table", "table", pos=(0.0, 0.0))
    b.add_object("Apple", "a1", pos=(0.0, 0.0, -2.0), movable=True)
    b.add_object("Apple", "a2", pos=(0.0, 0.0, -2.0), movable=True)
    return b


def test_build_forward_skips_contacts_and_gives_the_poses_of_a_full_forward() -> None:
    b = _parked_pair()
    model, data = b.build()
    assert model.opt.disableflags == 0  # the model's own flags are back
    assert data.ncon == 0
    full = mujoco.MjData(model)
    mujoco.mj_forward(model, full)
    assert full.ncon > 0  # the overlapping apples do touch: the build skipped real work
    for field in ("xpos", "xquat", "geom_xpos", "geom_xmat", "cam_xpos", "light_xpos"):
        assert np.array_equal(getattr(data, field), getattr(full, field)), field
    # a simulation started from the build is the simulation started from a full forward
    for _ in range(20):
        mujoco.mj_step(model, data)
        mujoco.mj_step(model, full)
    assert np.array_equal(data.qpos, full.qpos)


def test_compile_model_hands_out_separate_copies_equal_to_a_fresh_compile() -> None:
    xml = _parked_pair("copies").to_xml()
    first, second = compile_model(xml), compile_model(xml)
    fresh = mujoco.MjModel.from_xml_string(xml)
    assert first is not second
    first.geom_rgba[:] = 0.0  # an env recolouring its copy
    first.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    third = compile_model(xml)
    for field in ("geom_rgba", "geom_size", "geom_pos", "body_mass", "mesh_vert", "mesh_face", "tex_data"):
        assert np.array_equal(getattr(second, field), getattr(fresh, field)), field
        assert np.array_equal(getattr(third, field), getattr(fresh, field)), field
    assert third.opt.disableflags == fresh.opt.disableflags


def test_compile_model_keeps_only_the_most_recent_models() -> None:
    for k in range(MODEL_CACHE_SIZE + 3):
        b = SceneBuilder(name=f"lru{k}", offscreen=(64, 64))
        b.add_studio()
        compile_model(b.to_xml())
    assert len(scene_mod._MODELS) == MODEL_CACHE_SIZE


def test_compile_model_keeps_the_cache_under_its_byte_budget(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    xmls = []
    for k in range(3):
        b = SceneBuilder(name=f"budget{k}", offscreen=(64, 64))
        b.add_studio()
        xmls.append(b.to_xml())
    one = mujoco.mj_sizeModel(mujoco.MjModel.from_xml_string(xmls[0]))
    monkeypatch.setattr(scene_mod, "MODEL_CACHE_BYTES", int(2.5 * one))  # room for two of these models
    for xml in xmls:
        compile_model(xml)
    kept = [key[0] for key in scene_mod._MODELS]
    assert kept[-2:] == xmls[1:] and xmls[0] not in kept
    assert sum(size for _, size in scene_mod._MODELS.values()) <= 2.5 * one
    monkeypatch.setattr(scene_mod, "MODEL_CACHE_BYTES", one // 2)  # smaller than any model: the newest stays
    compile_model(xmls[0])
    assert [key[0] for key in scene_mod._MODELS] == [xmls[0]]
    assert MODEL_CACHE_BYTES > 33_000_000  # an EB-Manipulation model with its visual meshes fits


def test_a_cached_model_renders_the_bytes_of_a_fresh_compile() -> None:
    xml = _parked_pair("render").to_xml()
    compile_model(xml)  # now cached
    cam = free_camera((0.0, 0.0, 0.5), 2.5, 135.0, -25.0)
    images = []
    for model in (mujoco.MjModel.from_xml_string(xml), compile_model(xml)):
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        r = SceneRenderer(model, data, 64, 64)
        try:
            images.append(r.rgb(cam))
        finally:
            r.close()
    assert images[0].std() > 1.0  # the table is drawn, not an empty frame
    assert np.array_equal(images[0], images[1])


def test_quote_writes_what_quoteattr_writes() -> None:
    for text in ("0.25 -1 3", "room/wall_n", "a & b", "x<y>z", 'say "hi"', "it's", "both ' and \"", "tab\there",
                 "line\nbreak", ""):
        assert quote(text) == quoteattr(text), text
