"""The scripted expert: a plan of discrete 7-D actions that solves a task from a given state.

It works from a :class:`StateView` (object positions and yaws, what is held and how), which the world
provides for the current state and :func:`initial_state` builds from a scene spec alone (for the
in-context examples). Plans use only what an agent could also know: object coordinates rounded to bins,
plus the objects' yaw and the grasp offset, which a careful agent can read off the images.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from eb_manipulation.actions import angle_to_bin, bin_to_pos, pos_to_bin
from eb_manipulation.scene import CONTAINER, SORTER, SPONGE, TABLE_TOP, hole_centres
from eb_manipulation.shapes import CUBE_HALF, SHAPES
from eb_manipulation.spec import SceneSpec
from eb_manipulation.world import wipe_axes

__all__ = ["StateView", "expert_plan", "initial_state", "state_of_world"]

Action = tuple[int, int, int, int, int, int, int]

#: Rotational symmetry (degrees) of each shape about the vertical, for fitting a sorter hole.
SYMMETRY = {"cube": 90.0, "cylinder": 360.0, "star": 72.0, "triangle": 120.0, "moon": 360.0}


@dataclass
class StateView:
    positions: dict[str, np.ndarray]
    """Centre of each loose object (world, m)."""
    yaws: dict[str, float]
    held: str | None = None
    held_offset: np.ndarray | None = None
    """Held object's centre minus the tool point, in the world frame (m)."""
    gripper_open: bool = True
    tcp: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.1]))
    tcp_yaw: float = 0.0
    strokes_done: float = 0.0


def initial_state(scene: SceneSpec) -> StateView:
    """The state right after reset, computed from the spec (objects rest on the table)."""
    pos, yaw = {}, {}
    for o in scene.objects:
        if o.kind == "shape":
            pos[o.id] = np.array([o.x, o.y, TABLE_TOP + SHAPES[o.shape].height / 2])  # type: ignore[index]
        elif o.kind == "sponge":
            pos[o.id] = np.array([o.x, o.y, TABLE_TOP + SPONGE.size[2] / 2])
        else:
            continue
        yaw[o.id] = o.yaw
    return StateView(positions=pos, yaws=yaw)


def state_of_world(world) -> StateView:
    """The current state of a :class:`~eb_manipulation.world.World`."""
    pos, yaw = {}, {}
    for o in world.free_objects:
        pos[o] = world.body_pos(o)
        yaw[o] = world.yaw_of(o)
    p, R = world.arm.tcp()
    offset = None
    if world.held is not None:
        offset = pos[world.held] - p
    return StateView(positions=pos, yaws=yaw, held=world.held, held_offset=offset, gripper_open=world.gripper_open,
                     tcp=p, tcp_yaw=math.degrees(math.atan2(R[1, 0], R[0, 0])),
                     strokes_done=world.wiped_fraction)


def _wrap(a: float, period: float) -> float:
    """``a`` wrapped into [-period/2, period/2)."""
    return (a + period / 2) % period - period / 2


def _grip_yaw(obj_yaw: float) -> float:
    """A gripper yaw in [-90, 90) whose fingers close across the object's local y axis."""
    return _wrap(obj_yaw, 180.0)


def _act(x: float, y: float, z: float, yaw: float, open_: bool) -> Action:
    return (pos_to_bin(x, "x"), pos_to_bin(y, "y"), pos_to_bin(z, "z"), 120, 60, angle_to_bin(yaw), int(open_))


def _bin_centre_xy(x: float, y: float) -> tuple[float, float]:
    return bin_to_pos(pos_to_bin(x, "x"), "x"), bin_to_pos(pos_to_bin(y, "y"), "y")


def _grasp(state: StateView, obj: str, height_above: float = 0.10) -> tuple[list[Action], float, np.ndarray]:
    """Approach, descend and close on ``obj``. Returns actions, the gripper yaw, and the predicted offset
    (object centre minus tool point) once held."""
    p = state.positions[obj]
    yaw = _grip_yaw(state.yaws[obj])
    acts = [
        _act(p[0], p[1], p[2] + height_above, yaw, True),
        _act(p[0], p[1], p[2], yaw, True),
        _act(p[0], p[1], p[2], yaw, False),
    ]
    tx, ty = _bin_centre_xy(p[0], p[1])
    tz = bin_to_pos(pos_to_bin(p[2], "z"), "z")
    offset = np.array([p[0] - tx, p[1] - ty, p[2] - tz])
    # the closing fingers centre the object along their axis
    axis = np.array([-math.sin(math.radians(yaw)), math.cos(math.radians(yaw)), 0.0])
    offset -= axis * float(offset @ axis)
    return acts, yaw, offset


def _place_tcp(target_centre: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """Tool point that puts the held object's centre nearest ``target_centre`` (bins are 1 cm)."""
    want = target_centre - offset
    best, best_err = want, 1e9
    bx, by = pos_to_bin(want[0], "x"), pos_to_bin(want[1], "y")
    for ix in (bx - 1, bx, bx + 1):
        for iy in (by - 1, by, by + 1):
            c = np.array([bin_to_pos(ix, "x"), bin_to_pos(iy, "y"), want[2]])
            err = np.linalg.norm(c[:2] + offset[:2] - target_centre[:2])
            if err < best_err:
                best, best_err = c, err
    return best


def _holding(state: StateView, obj: str) -> tuple[list[Action], float, np.ndarray]:
    """Actions that end with ``obj`` held (empty if it already is), the gripper yaw and the offset."""
    if state.held == obj and state.held_offset is not None:
        return [], state.tcp_yaw, state.held_offset
    acts: list[Action] = []
    if state.held is not None or not state.gripper_open:
        # let go of whatever is held, straight up first
        acts.append(_act(state.tcp[0], state.tcp[1], state.tcp[2] + 0.03, state.tcp_yaw, True))
    g, yaw, off = _grasp(state, obj)
    return acts + g, yaw, off


def expert_plan(scene: SceneSpec, state: StateView) -> list[Action]:
    """Actions that solve ``scene``'s goal from ``state``."""
    g = scene.goal
    if g.family == "pick":
        return _plan_pick(scene, state)
    if g.family == "stack":
        return _plan_stack(scene, state)
    if g.family == "sorter":
        return _plan_sorter(scene, state)
    return _plan_wipe(scene, state)


def _plan_pick(scene: SceneSpec, state: StateView) -> list[Action]:
    g = scene.goal
    obj, cont = g.target, scene.get(g.container)  # type: ignore[arg-type]
    acts, yaw, off = _holding(state, obj)  # type: ignore[arg-type]
    h = SHAPES[scene.get(obj).shape].height  # type: ignore[arg-type, index]
    rim = TABLE_TOP + CONTAINER.height
    centre = np.array([cont.x, cont.y, rim + h / 2 + 0.03])
    tcp = _place_tcp(centre, off)
    zt = centre[2] - off[2]
    p = state.positions[obj] - (off if state.held == obj else 0.0)
    lift = max(p[2] + 0.12, zt)
    acts += [_act(p[0], p[1], lift, yaw, False), _act(tcp[0], tcp[1], zt, yaw, False),
             _act(tcp[0], tcp[1], zt, yaw, True)]
    return acts


def _plan_stack(scene: SceneSpec, state: StateView) -> list[Action]:
    order = list(scene.goal.order)
    side = 2 * CUBE_HALF
    # find how much of the tower already stands
    done = 1
    for below, above in zip(order[:-1], order[1:]):
        pa, pb = state.positions[above], state.positions[below]
        if state.held != above and np.linalg.norm(pa[:2] - pb[:2]) < 0.6 * side and 0.8 * side < pa[2] - pb[2] < 1.2 * side:
            done += 1
        else:
            break
    acts: list[Action] = []
    sv = state
    for k in range(done, len(order)):
        below, above = order[k - 1], order[k]
        a, yaw, off = _holding(sv, above)
        pb = sv.positions[below]
        target = np.array([pb[0], pb[1], pb[2] + side + 0.006])
        tcp = _place_tcp(target, off)
        # turn the held cube to line up with the one below (cubes repeat every 90 degrees)
        yaw_place = yaw + _wrap(sv.yaws[below] - sv.yaws[above], 90.0)
        zt = target[2] - off[2]
        a += [_act(tcp[0], tcp[1], zt + 0.06, yaw_place, False), _act(tcp[0], tcp[1], zt, yaw_place, False),
              _act(tcp[0], tcp[1], zt, yaw_place, True)]
        acts += a
        # predicted state after this placement
        new_pos = dict(sv.positions)
        new_pos[above] = np.array([pb[0], pb[1], pb[2] + side])
        new_yaw = dict(sv.yaws)
        new_yaw[above] = sv.yaws[below]
        sv = StateView(positions=new_pos, yaws=new_yaw, gripper_open=True,
                       tcp=np.array([tcp[0], tcp[1], zt]), tcp_yaw=yaw_place)
    return acts


def _plan_sorter(scene: SceneSpec, state: StateView) -> list[Action]:
    obj = scene.goal.target
    spec = scene.get(obj)  # type: ignore[arg-type]
    sorter = next(o for o in scene.objects if o.kind == "sorter")
    k = sorter.holes.index(spec.shape)  # type: ignore[arg-type]
    hx, hy = hole_centres(sorter)[k]
    acts, yaw, off = _holding(state, obj)  # type: ignore[arg-type]
    h = SHAPES[spec.shape].height  # type: ignore[index]
    # turn the held shape so it lines up with its hole (modulo the shape's symmetry)
    sym = SYMMETRY[spec.shape]  # type: ignore[index]
    delta = 0.0 if spec.shape == "cylinder" else _wrap(sorter.yaw - state.yaws[obj], sym)
    yaw_place = _wrap(yaw + delta, 360.0)
    c, s = math.cos(math.radians(delta)), math.sin(math.radians(delta))
    off_r = np.array([c * off[0] - s * off[1], s * off[0] + c * off[1], off[2]])
    plate_top = TABLE_TOP + SORTER.height
    target = np.array([hx, hy, plate_top + h / 2 + 0.015])
    tcp = _place_tcp(target, off_r)
    zt = target[2] - off_r[2]
    p = state.positions[obj] - (off if state.held == obj else 0.0)
    acts += [_act(p[0], p[1], max(p[2] + 0.12, zt + 0.05), yaw, False),
             _act(tcp[0], tcp[1], zt + 0.05, yaw_place, False), _act(tcp[0], tcp[1], zt, yaw_place, False),
             _act(tcp[0], tcp[1], zt, yaw_place, True)]
    return acts


def _plan_wipe(scene: SceneSpec, state: StateView) -> list[Action]:
    g = scene.goal
    sponge, area = g.target, scene.get(g.area)  # type: ignore[arg-type]
    acts, yaw, off = _holding(state, sponge)  # type: ignore[arg-type]
    axis, sign, start, end, l_lo, l_hi = wipe_axes(area, g.direction)  # type: ignore[arg-type]
    lateral = (l_lo + l_hi) / 2
    u0 = start - sign * 0.01
    u1 = end + sign * 0.015
    z_contact = TABLE_TOP + SPONGE.size[2] / 2 + 0.002

    def point(u: float) -> np.ndarray:
        return np.array([u, lateral, z_contact]) if axis == 0 else np.array([lateral, u, z_contact])

    p0, p1 = point(u0), point(u1)
    t0, t1 = _place_tcp(p0, off), _place_tcp(p1, off)
    zt = z_contact - off[2]
    acts += [_act(t0[0], t0[1], zt + 0.06, yaw, False), _act(t0[0], t0[1], zt, yaw, False),
             _act(t1[0], t1[1], zt, yaw, False)]
    return acts
