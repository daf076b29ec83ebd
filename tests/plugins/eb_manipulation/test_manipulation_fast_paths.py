"""The cheaper ways of drawing and planning give what the plain ways give.

* the front camera's colour pass without the skybox: the same pixels as MuJoCo's full pass;
* boxes from our decode of the segmentation pass: the same as from ``mujoco.Renderer``'s segmentation mode;
* frame reuse (a failed action moves nothing; a task reset again): the same observations as an env that draws
  every frame, and no pass drawn where nothing changed;
* the numpy contact filter of the arm: the same contacts as a plain loop over MuJoCo's contact list.
"""

from __future__ import annotations

import numpy as np
import pytest

from eb_scenekit.gl import import_mujoco

from eb_manipulation import render as manip_render
from eb_manipulation.env import ManipulationEnv
from eb_manipulation.oracle import expert_plan, state_of_world
from eb_manipulation.render import SKY_HIDDEN, SceneRenderer
from eb_manipulation.tasks import scene_of
from eb_manipulation.world import World

mujoco = import_mujoco()

RES = 160


def _groups(world: World) -> dict[str, set[int]]:
    keys = {o.key for o in world.objects}
    out: dict[str, set[int]] = {}
    for g in world.geom_owner:
        key = world.model.geom(g).name.split("#")[0]
        if key in keys:
            out.setdefault(key, set()).add(g)
    return out


def _reference_boxes(r, data, camera: str, groups: dict[str, set[int]]) -> dict[str, tuple[int, int, int, int]]:
    """Boxes the plain way: mujoco.Renderer's segmentation mode, then a mask per group."""
    r.enable_segmentation_rendering()
    try:
        r.update_scene(data, camera)
        seg = r.render()
    finally:
        r.disable_segmentation_rendering()
    ids = seg[..., 0].astype(np.int64)
    ids[seg[..., 1] != int(mujoco.mjtObj.mjOBJ_GEOM)] = -1
    out = {}
    for key, geoms in groups.items():
        mask = np.isin(ids, list(geoms))
        if mask.sum() >= 4:
            ys, xs = np.nonzero(mask)
            out[key] = (int(xs.min()), int(ys.min()), int(xs.max()), int(ys.max()))
    return out


def _states(world: World, steps: int):
    """The world's current state, then the states after each of the expert's next ``steps`` actions."""
    yield
    for _ in range(steps):
        plan = expert_plan(world.scene, state_of_world(world))
        if not plan:
            return
        assert world.execute(tuple(plan[0])).ok
        yield


def test_front_without_skybox_and_decoded_boxes_match_mujocos_own_passes() -> None:
    assert "front" in SKY_HIDDEN and "wrist" not in SKY_HIDDEN  # the wrist camera can look at the horizon
    picked = {}
    for t in ManipulationEnv.load_tasks():
        picked.setdefault(t.metadata["family"], t)
    checked = 0
    for task in picked.values():
        world = World(scene_of(task), resolution=RES)  # with the arm's visual meshes, no env drawing on the side
        ours = SceneRenderer(world.model, RES, pooled=False)
        ours.reuse_frames = False
        plain = mujoco.Renderer(world.model, RES, RES)
        try:
            for _ in _states(world, steps=1):
                plain.update_scene(world.data, "front")
                assert plain.scene.flags[int(mujoco.mjtRndFlag.mjRND_SKYBOX)]  # the plain pass draws the sky
                want = plain.render().copy()
                assert np.array_equal(ours.rgb(world.data, "front"), want)
                groups = _groups(world)
                boxes = ours.boxes(world.data, "front", groups)
                assert boxes == _reference_boxes(plain, world.data, "front", groups)
                assert len(boxes) >= 3  # real boxes compared, not two empty dicts
                plain.update_scene(world.data, "wrist")
                assert np.array_equal(ours.rgb(world.data, "wrist"), plain.render())
                checked += 1
        finally:
            plain.close()
            ours.close()
    assert checked >= 8


def _snap(obs) -> tuple[dict[str, bytes], list]:
    return ({k: v.tobytes() for k, v in obs.images.items()}, [(o.name, o.box, o.position) for o in obs.objects])


def _episode(env: ManipulationEnv, task, actions) -> list:
    out = [_snap(env.reset(task, 0))]
    for a in actions:
        r = env.step(a)
        out.append((_snap(r.observation), r.action_success, r.feedback))
    return out


def test_frame_reuse_gives_the_frames_a_full_draw_gives(monkeypatch: pytest.MonkeyPatch) -> None:
    tasks = ManipulationEnv.load_tasks()
    task = next(t for t in tasks if t.metadata["family"] == "pick")
    probe = ManipulationEnv(render=False)
    probe.reset(task, 0)
    plan = probe.expert_plan() or []
    probe.close()
    unreachable = (100, 100, 100, 0, 60, 0, 1)  # front right corner, 1.6 m high: out of reach, nothing moves
    actions = [plan[0], unreachable, plan[1], unreachable, unreachable, plan[2]]

    monkeypatch.setattr(manip_render, "_FIRST", type(manip_render._FIRST)())  # no first frames of earlier tests
    monkeypatch.setattr(manip_render, "REUSE_FRAMES", False)
    plain = ManipulationEnv(resolution=RES, multi_view=True)
    try:
        want = _episode(plain, task, actions)
        assert plain._renderer.frames_reused == 0  # noqa: SLF001
    finally:
        plain.close()
    monkeypatch.setattr(manip_render, "REUSE_FRAMES", True)
    env = ManipulationEnv(resolution=RES, multi_view=True)
    try:
        got = _episode(env, task, actions)
        r = env._renderer  # noqa: SLF001
        # 3 of the 6 actions failed: their front, wrist and segmentation passes were not drawn again
        assert [g[1] for g in got[1:]] == [True, False, True, False, False, True]
        assert r.frames_reused == 3 * 3
        assert r.frames_drawn == 3 * 4  # reset + 3 moves
        assert got == want
        # the same task again in a fresh env of this process: its first frames come from the cache, same pixels
        again = ManipulationEnv(resolution=RES, multi_view=True)
        try:
            first = _snap(again.reset(task, 0))
            assert again._renderer.frames_drawn == 0 and again._renderer.frames_reused == 3  # noqa: SLF001
            assert first == want[0]
            moved = again.step(plan[0])
            assert _snap(moved.observation) == want[1][0] and again._renderer.frames_drawn == 3  # noqa: SLF001
        finally:
            again.close()
    finally:
        env.close()
    assert want[1][0] != want[0] and want[2][0] == want[1][0]  # the arm moved, then a failed action moved nothing


def _plain_contacts(arm, held: str | None) -> dict[tuple[int, int], float]:
    """The arm's contact filter as a plain loop over MuJoCo's contact list (the reference)."""
    mujoco.mj_kinematics(arm.m, arm.d)
    mujoco.mj_collision(arm.m, arm.d)
    out: dict[tuple[int, int], float] = {}
    for i in range(arm.d.ncon):
        c = arm.d.contact[i]
        g1, g2 = int(c.geom1), int(c.geom2)
        a_robot, b_robot = g1 in arm.robot_geoms, g2 in arm.robot_geoms
        a_held = held is not None and arm.geom_owner.get(g1) == held
        b_held = held is not None and arm.geom_owner.get(g2) == held
        if (a_robot and b_held) or (b_robot and a_held) or (a_robot and b_robot):
            continue
        if a_robot or a_held:
            key = (g1, g2)
        elif b_robot or b_held:
            key = (g2, g1)
        else:
            continue
        out[key] = min(out.get(key, 1.0), float(c.dist))
    return out


def test_contact_filter_matches_a_plain_loop(env: ManipulationEnv, tasks) -> None:
    task = next(t for t in tasks.values() if t.metadata["family"] == "wipe")
    env.reset(task, 0)
    world = env._world  # noqa: SLF001
    arm = world.arm
    seen_held = seen_robot = 0
    for action in (env.expert_plan() or [])[:4]:
        # poses along the way down to the sponge and with the sponge held, pressed a little into the table
        q0 = arm.q()
        res = arm.plan(*_pose(action), world.held, world._place_held)  # noqa: SLF001
        for q in (res.path or [q0])[-6:]:
            arm.set_q(q)
            world._place_held(q)  # noqa: SLF001
            for held in {world.held, None}:
                ours = arm.contacts(held)
                assert ours == _plain_contacts(arm, held)
                assert list(ours) == list(_plain_contacts(arm, held))  # same order: the same blocker on ties
                seen_robot += any(k[0] in arm.robot_geoms for k in ours)
                seen_held += held is not None and any(k[0] not in arm.robot_geoms for k in ours)
        arm.set_q(q0)
        world._place_held(q0)  # noqa: SLF001
        env.step(action)
    assert seen_robot and seen_held  # contacts of the fingers and of the held sponge were compared


def _pose(action):
    from eb_manipulation.actions import bin_to_angle, bin_to_pos, euler_to_matrix

    p = np.array([bin_to_pos(action[i], ax) for i, ax in enumerate("xyz")])
    return p, euler_to_matrix(*(bin_to_angle(action[3 + i]) for i in range(3)))
