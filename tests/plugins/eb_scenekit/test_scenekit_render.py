"""Renderer: RGB/depth/segmentation shapes and values, boxes in view and behind, moving cameras, sheets."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from eb_scenekit import (
    SceneBuilder, SceneRenderer, camera_from_eye, contact_sheet, free_camera, save_png, set_agent_pose,
)
from eb_scenekit._mujoco import mujoco


@pytest.fixture(scope="module")
def scene():  # type: ignore[no-untyped-def]
    b = SceneBuilder()
    b.add_room("kitchen", (4.0, 4.0), seed=1, door=("south", 1.2), windows=[("north", 0.0)])
    b.add_object("Fridge", "fridge", (1.6, 1.6), yaw=-90)
    b.add_object("DiningTable", "table", (0.0, 0.0))
    b.add_object("Apple", "apple", (0.0, 0.2), parent="table")
    b.add_object("Mug", "mug", (0.0, -0.3), parent="table")
    b.add_object("Sofa", "sofa", (-1.5, 0.0), yaw=0)
    b.add_camera("front", (2.0, 0.0, 1.5), lookat=(0.0, 0.0, 0.8))
    b.add_agent_camera("agent", (1.5, -1.5), yaw=135, pitch=-20)
    model, data = b.build()
    with SceneRenderer(model, data) as r:
        yield r


def test_rgb_depth_segmentation_shapes(scene) -> None:  # type: ignore[no-untyped-def]
    rgb = scene.rgb("front")
    depth = scene.depth("front")
    seg = scene.segmentation("front")
    assert rgb.shape == (500, 500, 3) and rgb.dtype == np.uint8
    assert depth.shape == (500, 500) and depth.dtype == np.float32
    assert seg.shape == (500, 500) and seg.dtype == np.int32
    assert rgb.mean() > 90, "renders are bright"
    assert (depth > 0).all() and depth.max() < 10.0
    table = seg == scene.instance_ids["table"]
    # the table is ~2 m away from the camera
    assert 1.2 < float(np.median(depth[table])) < 2.6
    assert set(np.unique(seg)) <= set(range(len(scene.instance_names)))


def test_boxes_for_objects_in_view_and_none_behind(scene) -> None:  # type: ignore[no-untyped-def]
    boxes = scene.boxes("front")
    assert {"table", "apple", "mug", "sofa"} <= set(boxes)
    assert "fridge" not in boxes  # behind and to the side of the camera at x=2 looking to -x
    x0, y0, x1, y1 = boxes["apple"]
    assert 0 <= x0 <= x1 < 500 and 0 <= y0 <= y1 < 500
    tx0, ty0, tx1, ty1 = boxes["table"]
    assert tx0 <= x0 and x1 <= tx1
    behind = scene.boxes(camera_from_eye((-1.0, 0.0, 1.4), (-3.0, 0.0, 1.2)))
    assert "table" not in behind and "apple" not in behind


def test_free_and_agent_cameras_move_without_recompiling(scene) -> None:  # type: ignore[no-untyped-def]
    a = scene.rgb("agent")
    set_agent_pose(scene.model, scene.data, "agent", (1.5, -1.5), yaw=135 + 180, pitch=0)
    b = scene.rgb("agent")
    assert not np.array_equal(a, b)
    set_agent_pose(scene.model, scene.data, "agent", (1.5, -1.5, 1.5), yaw=135, pitch=-20)
    assert np.array_equal(scene.rgb("agent"), a)
    top = free_camera((0, 0, 0.8), 2.5, 90, -89)
    assert "apple" in scene.boxes(top)


def test_overhead_hides_ceiling_and_agent_markers(scene) -> None:  # type: ignore[no-untyped-def]
    overhead = camera_from_eye((0.0, -0.01, 6.0), (0.0, 0.0, 0.0))
    assert "table" in scene.boxes(overhead)
    with_agent = scene.rgb(overhead, show_agents=True)
    without = scene.rgb(overhead)
    assert not np.array_equal(with_agent, without)


def test_other_sizes_and_700px(scene) -> None:  # type: ignore[no-untyped-def]
    assert scene.rgb("front", 300, 300).shape == (300, 300, 3)
    assert scene.rgb("front", 700, 700).shape == (700, 700, 3)
    assert scene.segmentation("front", 700, 700).shape == (700, 700)


def test_unknown_camera_lists_cameras(scene) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(KeyError, match="front"):
        scene.rgb("nope")


def test_png_and_contact_sheet(tmp_path, scene) -> None:  # type: ignore[no-untyped-def]
    img = scene.rgb("front", 64, 64)
    sheet = contact_sheet([img, img, img], ["one", "two", "three"], cols=2)
    assert sheet.shape[1] > 2 * 64 and sheet.shape[0] > 2 * 64 and sheet.dtype == np.uint8
    path = save_png(tmp_path / "sub" / "sheet.png", sheet)
    assert np.array_equal(np.asarray(Image.open(path)), sheet)
    with pytest.raises(ValueError):
        contact_sheet([img], ["a", "b"])


def test_plain_models_segment_by_name_prefix() -> None:
    xml = """<mujoco><worldbody><light pos="0 0 3"/>
      <geom name="cube/body" type="box" size=".2 .2 .2" rgba="1 0 0 1"/>
      <camera name="c" pos="0 -2 1" xyaxes="1 0 0 0 .45 .9"/></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    with SceneRenderer(model, data, 64, 64) as r:
        assert r.instance_names == ["", "cube"]
        assert "cube" in r.boxes("c")


def test_pool_private_switch_and_errors(scene, monkeypatch: pytest.MonkeyPatch) -> None:  # type: ignore[no-untyped-def]
    """Scene renderers share the thread's pool unless told (or EB_SCENEKIT_PRIVATE_GL=1); same pixels either way,
    depth and segmentation included; a closed or too-large request fails in one line."""
    from eb_scenekit import pool

    assert scene.pooled and pool.pool_stats()["live"] == 1
    monkeypatch.setenv(pool.PRIVATE_GL_ENV, "1")
    with SceneRenderer(scene.model, scene.data) as private:
        assert not private.pooled
        for fn in ("rgb", "depth", "segmentation"):
            a, b = getattr(private, fn)("agent", 200, 160), getattr(scene, fn)("agent", 200, 160)
            assert a.shape == (160, 200) + a.shape[2:] and np.array_equal(a, b)
    monkeypatch.delenv(pool.PRIVATE_GL_ENV)
    other = SceneRenderer(scene.model, scene.data, 64, 64)
    assert other.pooled and pool.pool_stats()["users"] >= 2
    with pytest.raises(ValueError, match="larger than this scene's offscreen buffer"):
        other.rgb("agent", 4000, 4000)
    other.close()
    with pytest.raises(RuntimeError, match="closed"):
        other.rgb("agent")
    assert pool.pool_stats()["live"] == 1  # the fixture's renderer still holds the pool


def _scene_with(objects: list[tuple[str, str, tuple[float, float]]]):  # type: ignore[no-untyped-def]
    b = SceneBuilder()
    b.add_room("kitchen", (4.0, 4.0), seed=2)
    for name, kind, xy in objects:
        b.add_object(name, kind, xy)
    b.add_agent_camera("agent", (1.5, -1.5), yaw=135, pitch=-20)
    return b.build()


def test_pool_context_cache_budget_release_and_bad_setting(monkeypatch: pytest.MonkeyPatch) -> None:
    """Scenes taking turns on one thread keep GL contexts of their own while the estimated sizes fit
    EB_SCENEKIT_GL_CACHE_MB, scenes with the same render assets draw with one, the rest share one rebuilt
    context; a released scene's context is freed when no scene uses it and its room goes to a scene that draws
    next; every frame equals a private renderer's; a bad setting is one clear line.
    Runs on a thread of its own: a fresh pool, whatever other tests of this process hold."""
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(1) as ex:
        ex.submit(_cache_scenario, monkeypatch).result()


def _cache_scenario(monkeypatch: pytest.MonkeyPatch) -> None:
    from eb_scenekit import pool

    # a fridge and a table are built from primitives only (the same render assets: the room's textures), so are
    # two mugs at different places; the sofa and the apple have meshes of their own
    specs = [[("Fridge", "fridge", (1.6, 1.6))], [("DiningTable", "table", (0.0, 0.0))],
             [("Sofa", "sofa", (-1.5, 0.0))], [("Mug", "mug", (0.0, 0.0))], [("Mug", "mug", (0.8, -0.5))],
             [("Apple", "apple", (0.0, 0.3))]]
    worlds = [_scene_with(spec) for spec in specs]
    digests = [pool.render_assets(m) for m, _ in worlds]
    assert digests[0] == digests[1] and digests[3] == digests[4] and len(set(digests)) == 4
    monkeypatch.setenv(pool.PRIVATE_GL_ENV, "1")
    want = []
    for model, data in worlds:
        with SceneRenderer(model, data, 96, 96) as r:
            want.append(r.rgb("agent"))
    monkeypatch.delenv(pool.PRIVATE_GL_ENV)
    assert len({w.tobytes() for w in want}) == 6  # six different pictures

    sizes = [pool.context_mb(m) for m, _ in worlds]
    assert all(1 < s < 100 for s in sizes)
    monkeypatch.setenv(pool.CACHE_ENV, str(sizes[2] + sizes[3] + 0.01))  # room for the sofa's and the mugs'
    renderers = [SceneRenderer(m, d, 96, 96) for m, d in worlds]
    for r in renderers:
        r.reuse_frames = False  # every call draws (and so switches the pool)
    try:
        before = pool.pool_stats()
        for _ in range(3):
            for r, w in zip(renderers, want):
                assert np.array_equal(r.rgb("agent"), w)
        stats = {k: v - before[k] if k in ("cached", "shared", "rebinds") else v
                 for k, v in pool.pool_stats().items()}
        # the fridge made the shared context and the table draws with it; the sofa and the first mug got their
        # own, the second mug draws with the first's; the apple rebuilds the shared context on each of its turns
        # and the fridge rebuilds it back on each of its later ones (the table then joins it again)
        assert stats["cached"] == 2 and stats["cached_live"] == 2
        assert abs(stats["cached_mb"] - round(sizes[2] + sizes[3], 1)) < 0.2
        assert stats["shared"] == 2 + 2 and stats["rebinds"] == 5
        renderers[3].close()  # the second mug still draws with that context
        assert pool.pool_stats()["cached_live"] == 2
        renderers[4].close()  # now it is freed (this thread's): its room goes to the next scene without one
        assert pool.pool_stats()["cached_live"] == 1
        monkeypatch.setenv(pool.CACHE_ENV, str(sizes[0] + sizes[2] + 0.01))
        for i in (2, 5, 0, 1):  # sofa (own), apple (holds the shared one), fridge (cached now), table (joins it)
            assert np.array_equal(renderers[i].rgb("agent"), want[i])
        assert pool.pool_stats()["cached_live"] == 2
        monkeypatch.setenv(pool.CACHE_ENV, "lots")
        with pytest.raises(ValueError, match="EB_SCENEKIT_GL_CACHE_MB='lots' is not a number of megabytes"):
            pool.cache_budget_mb()
    finally:
        for r in renderers:
            r.close()
    assert pool.pool_stats()["cached_live"] == 0


def test_frame_reuse_equals_drawing_every_frame() -> None:
    """A renderer that reuses frames gives, after every kind of change a world makes (an object moved, a door
    opened, a lamp switched, a colour changed, the agent camera moved) and after none, exactly the images of one
    that draws every frame; it draws only when something changed or another camera, size or kind is asked for."""
    from eb_scenekit.render import draw_inputs
    from eb_scenekit.objects import set_object_pose, set_open, set_powered

    b = SceneBuilder()
    b.add_room("kitchen", (4.0, 4.0), seed=3)
    b.add_object("Fridge", "fridge", (1.4, 1.4), yaw=-135)
    b.add_object("DiningTable", "table", (0.0, 0.0))
    b.add_object("Apple", "apple", (0.0, 0.1), parent="table")
    b.add_object("DeskLamp", "lamp", (0.2, -0.2), parent="table")
    b.add_agent_camera("agent", (-1.4, -1.4), yaw=45, pitch=-15)
    model, data = b.build()
    reuse, fresh = SceneRenderer(model, data, 120, 120), SceneRenderer(model, data, 120, 120)
    fresh.reuse_frames = False
    overhead = free_camera((0.0, 0.0, 0.5), 5.0, 90.0, -75.0)

    def same(expect_draw: bool) -> None:
        before = reuse.frames_drawn
        for kind, args in (("rgb", ("agent",)), ("segmentation", ("agent",)), ("depth", ("agent",)),
                           ("rgb", (overhead, 80, 60))):
            a, b_ = getattr(reuse, kind)(*args), getattr(fresh, kind)(*args)
            assert a.dtype == b_.dtype and np.array_equal(a, b_), kind
        assert (reuse.frames_drawn > before) == expect_draw

    try:
        same(True)
        same(False)  # nothing changed: all four are copies
        img = reuse.rgb("agent")
        img[:] = 0  # a caller editing its copy does not change the next one
        assert np.array_equal(reuse.rgb("agent"), fresh.rgb("agent"))
        changes = [
            lambda: set_object_pose(model, data, "apple", (0.3, 0.0, 0.8)),
            lambda: set_open(model, data, "fridge", 1.0),
            lambda: set_powered(model, "lamp", False),  # lamps are built switched on
            lambda: model.geom_rgba.__setitem__((slice(None), 0), 0.2),
            lambda: set_agent_pose(model, data, "agent", (-1.2, -1.4, 1.5), yaw=40, pitch=-20),
        ]
        for change in changes:
            change()
            mujoco.mj_forward(model, data)
            same(True)
            same(False)
        reuse.show_ceiling = True  # an option the key carries
        fresh.show_ceiling = True
        same(True)
        assert reuse.frames_reused == 6 * 4 + 2  # every same(False) and the two rgb() after the edit
        kept = draw_inputs(model, data)
        assert all(isinstance(a, np.ndarray) for a in kept)
    finally:
        reuse.close()
        fresh.close()
