"""The scripted expert: a plan of discrete 7-D actions that reaches a task's goal from the CURRENT state.

The plan is a function of the whole state (:class:`StateView`): where every loose object is and how it is
turned, where the tool point is and how the gripper is oriented, whether the gripper is open, and what it
holds with which offset. So it can be asked again after every single action (closed loop) or from any
state a detour led to: steps whose effect already holds are not repeated (the arm already above the
object, already at the grasp pose, already at the drop pose...), a wrong object in the gripper or a gripper
closed on nothing is released first, a cube sitting where the tower must stand is moved aside first.

When the goal can no longer be reached (an object the goal needs fell off the table or out of the arm's
reach, or dropped into the wrong compartment of the shape sorter) :func:`expert_plan` raises
:class:`NoPlan` with the reason; the env turns that into ``expert_plan() -> None`` and ``expert_reason``.

Plans use what an agent could also know: object coordinates, the objects' yaw and the grasp offset, which a
careful agent can read off the images. Optional steps depend on the layout: the arm approaches from above
only when another object stands close to the one it grasps, and lifts a held object before carrying it only
when something stands near the way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from eb_manipulation.actions import angle_to_bin, bin_to_pos, pos_to_bin
from eb_manipulation.scene import CONTAINER, SORTER, SPONGE, TABLE_TOP, hole_centres
from eb_manipulation.shapes import CUBE_HALF, SHAPES, SYMMETRY
from eb_manipulation.spec import FLUSH_TOLERANCE, ObjectSpec, SceneSpec
from eb_manipulation.world import wipe_axes

__all__ = ["NoPlan", "StateView", "expert_plan", "initial_state", "state_of_world"]

Action = tuple[int, int, int, int, int, int, int]

#: Another object's centre closer than this (m) to the one being grasped: approach from above first.
CROWDED = 0.13
#: Another object's centre closer than this (m) to the carrying segment: lift before carrying.
NEAR_WAY = 0.07
#: How close (m, degrees) the tool must be to a pose for the step that goes there to count as done.
POS_TOL, YAW_TOL = 0.012, 4.5
#: Where the arm reaches objects on the table (distance from the robot base in the table plane, m).
REACH = 0.78
ROBOT_XY = (-0.3, 0.0)


class NoPlan(Exception):
    """The goal cannot be reached from this state. ``reason`` names objects as ``{obj}``, resolved by the env."""

    def __init__(self, reason: str, obj: str | None = None):
        super().__init__(reason)
        self.reason = reason
        self.obj = obj


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
    tcp_down: bool = False
    """The gripper points straight down (the orientation every expert action uses)."""
    strokes_done: float = 0.0


def initial_state(scene: SceneSpec) -> StateView:
    """The state right after reset, computed from the spec (objects rest on the table)."""
    pos, yaw = {}, {}
    for o in scene.objects:
        if o.kind == "shape":
            z, below = TABLE_TOP + SHAPES[o.shape_name].height / 2, o.on
            while below is not None:
                z += SHAPES[scene.get(below).shape_name].height
                below = scene.get(below).on
            pos[o.id] = np.array([o.x, o.y, z])
        elif o.kind == "sponge":
            pos[o.id] = np.array([o.x, o.y, TABLE_TOP + SPONGE.dims(o)[2] / 2])
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
                     tcp=p, tcp_yaw=math.degrees(math.atan2(R[1, 0], R[0, 0])), tcp_down=bool(R[2, 2] < -0.995),
                     strokes_done=world.wiped_fraction)


# --- small helpers ----------------------------------------------------------------------------------------
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


def _at(state: StateView, action: Action) -> bool:
    """The tool already stands at the pose of ``action`` (pointing down, same yaw)."""
    if not state.tcp_down:
        return False
    goal = np.array([bin_to_pos(action[i], ax) for i, ax in enumerate("xyz")])
    yaw = action[5] * 3.0 - 180.0
    return (float(np.abs(state.tcp - goal).max()) <= POS_TOL
            and abs(_wrap(state.tcp_yaw - yaw, 360.0)) <= YAW_TOL)


def _resting_z(scene: SceneSpec, obj: str) -> float:
    spec = scene.get(obj)
    if spec.kind == "sponge":
        return TABLE_TOP + SPONGE.dims(spec)[2] / 2
    return TABLE_TOP + SHAPES[spec.shape_name].height / 2


def _fixed_obstacles(scene: SceneSpec, skip: tuple[str, ...] = ()) -> list[tuple[float, float, float]]:
    """(x, y, radius) of containers and sorters (the things that do not move)."""
    out = []
    for o in scene.objects:
        if o.id in skip:
            continue
        if o.kind == "container":
            out.append((o.x, o.y, CONTAINER.inner / 2 + CONTAINER.wall))
        elif o.kind == "sorter":
            for hx, hy in hole_centres(o):
                out.append((hx, hy, SORTER.depth / 2))
    return out


def _crowded(scene: SceneSpec, state: StateView, obj: str) -> bool:
    """Something stands close to ``obj`` (or it is not on the table top): approach it from above."""
    p = state.positions[obj]
    if p[2] > _resting_z(scene, obj) + 0.01:
        return True
    for other, q in state.positions.items():
        if other != obj and other != state.held and float(np.hypot(*(q[:2] - p[:2]))) < CROWDED:
            return True
    return any(float(np.hypot(x - p[0], y - p[1])) < r + 0.05 for x, y, r in _fixed_obstacles(scene))


def _seg_dist(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    ab = b - a
    t = 0.0 if float(ab @ ab) < 1e-12 else min(max(float((p - a) @ ab) / float(ab @ ab), 0.0), 1.0)
    return float(np.linalg.norm(p - (a + t * ab)))


def _way_blocked(scene: SceneSpec, state: StateView, obj: str, a: np.ndarray, b: np.ndarray,
                 goal_ids: tuple[str, ...]) -> bool:
    """Another object stands near the straight way from ``a`` to ``b`` (table plane) while ``obj`` is carried."""
    for other, q in state.positions.items():
        if other != obj and _seg_dist(q[:2], a[:2], b[:2]) < NEAR_WAY:
            return True
    return any(_seg_dist(np.array([x, y]), a[:2], b[:2]) < r + 0.03
               for x, y, r in _fixed_obstacles(scene, skip=goal_ids))


def _check_reachable(scene: SceneSpec, state: StateView, objs) -> None:
    for obj in objs:
        p = state.positions[obj]
        if p[2] < TABLE_TOP - 0.03:
            raise NoPlan("{obj} fell off the table", obj)
        if state.held != obj and float(np.hypot(p[0] - ROBOT_XY[0], p[1] - ROBOT_XY[1])) > REACH:
            raise NoPlan("{obj} lies out of the arm's reach", obj)


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


# --- grasping ---------------------------------------------------------------------------------------------
#: Half the distance between the open fingers' outer faces (m).
FINGER_REACH = 0.055
#: Half a finger's width across the closing direction (m).
FINGER_HALF_WIDTH = 0.013


def _clear_yaw(scene: SceneSpec, state: StateView, obj: str) -> float:
    """The grasp yaw: across the object's local y axis, or turned by 90 or 45 degrees when an open finger would
    land on a container or sorter wall or on another object (an object that came to rest beside a wall)."""
    p = state.positions[obj]
    base = _grip_yaw(state.yaws[obj])
    others = [q[:2] for o, q in state.positions.items() if o != obj and o != state.held]
    fixed = _fixed_obstacles(scene)

    def clear(yaw: float, with_objects: bool) -> bool:
        axis = np.array([-math.sin(math.radians(yaw)), math.cos(math.radians(yaw))])
        side = np.array([axis[1], -axis[0]]) * FINGER_HALF_WIDTH
        tips = [p[:2] + FINGER_REACH * axis, p[:2] - FINGER_REACH * axis]
        for f in tips + [t + side for t in tips] + [t - side for t in tips]:
            if with_objects and any(np.linalg.norm(f - q) < 0.03 for q in others):
                return False
            if any(abs(f[0] - x) < r + 0.012 and abs(f[1] - y) < r + 0.012 for x, y, r in fixed):
                return False
        return True

    for with_objects in (True, False):
        for delta in (0.0, 90.0, 45.0, -45.0):
            if clear(base + delta, with_objects):
                return _wrap(base + delta, 180.0)
    if p[2] < _resting_z(scene, obj) + 0.01:  # on the table, pressed against a wall on several sides
        raise NoPlan("{obj} lies against a container or the shape sorter where the fingers cannot reach around it",
                     obj)
    return base


def _holding(scene: SceneSpec, state: StateView, obj: str) -> tuple[list[Action], float, np.ndarray, bool]:
    """Actions that end with ``obj`` held (none if it already is), the gripper yaw, the predicted offset
    (object centre minus tool point) once held, and whether the arm is still low at the object."""
    if state.held == obj and state.held_offset is not None:
        low = state.tcp[2] + state.held_offset[2] < _resting_z(scene, obj) + 0.03
        return [], state.tcp_yaw, state.held_offset, low
    acts: list[Action] = []
    if state.held is not None or not state.gripper_open:
        # let go of whatever is held (or open a gripper closed on nothing), a little higher than now
        acts.append(_act(state.tcp[0], state.tcp[1], state.tcp[2] + 0.03, state.tcp_yaw, True))
    p = state.positions[obj]
    yaw = _clear_yaw(scene, state, obj)
    above = _act(p[0], p[1], p[2] + 0.10, yaw, True)
    grasp_open = _act(p[0], p[1], p[2], yaw, True)
    close = _act(p[0], p[1], p[2], yaw, False)
    if acts:
        acts += [above, grasp_open, close]
    elif _at(state, grasp_open):
        acts = [close]
    elif _at(state, above):
        acts = [grasp_open, close]
    elif _crowded(scene, state, obj):
        acts = [above, grasp_open, close]
    else:
        acts = [grasp_open, close]
    tx, ty = _bin_centre_xy(p[0], p[1])
    tz = bin_to_pos(pos_to_bin(p[2], "z"), "z")
    offset = np.array([p[0] - tx, p[1] - ty, p[2] - tz])
    # the closing fingers centre the object along their axis
    axis = np.array([-math.sin(math.radians(yaw)), math.cos(math.radians(yaw)), 0.0])
    offset -= axis * float(offset @ axis)
    return acts, yaw, offset, True


def _carry(scene: SceneSpec, state: StateView, obj: str, acts: list[Action], yaw: float, off: np.ndarray,
           low: bool, goal_ids: tuple[str, ...], steps: list[Action]) -> list[Action]:
    """Append the carrying ``steps`` (ending with the release) to ``acts``, skipping those already done and
    lifting first when the held object is low and something stands near the way."""
    if not acts:  # already holding it: resume where the arm stands
        for i in range(len(steps) - 1, -1, -1):
            if _at(state, steps[i]):
                return steps[i + 1:] if i + 1 < len(steps) else steps[i:]
    tcp_now = state.tcp if not acts else None
    start = (state.positions[obj] - off) if tcp_now is None else tcp_now
    first = np.array([bin_to_pos(steps[0][0], "x"), bin_to_pos(steps[0][1], "y"), 0.0])
    if low and _way_blocked(scene, state, obj, start, first, goal_ids):
        z_lift = max(_resting_z(scene, obj) - off[2] + 0.12, bin_to_pos(steps[0][2], "z"))
        acts = acts + [_act(start[0], start[1], z_lift, yaw, False)]
    return acts + steps


# --- families ---------------------------------------------------------------------------------------------
def expert_plan(scene: SceneSpec, state: StateView) -> list[Action]:
    """Actions that solve ``scene``'s goal from ``state``; raises :class:`NoPlan` when that is impossible."""
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
    obj, cont = g.target_id, scene.get(g.container)
    _check_reachable(scene, state, [obj])
    acts, yaw, off, low = _holding(scene, state, obj)
    h = SHAPES[scene.get(obj).shape_name].height
    centre = np.array([cont.x, cont.y, TABLE_TOP + CONTAINER.height + h / 2 + 0.03])
    tcp = _place_tcp(centre, off)
    zt = centre[2] - off[2]
    steps = [_act(tcp[0], tcp[1], zt, yaw, False), _act(tcp[0], tcp[1], zt, yaw, True)]
    return _carry(scene, state, obj, acts, yaw, off, low, (cont.id,), steps)


def _in_own_compartment(sorter: ObjectSpec, spec: ObjectSpec, p: np.ndarray) -> bool:
    """``p`` (the centre of shape ``spec``) lies in the compartment under the hole of its own shape."""
    if spec.shape not in sorter.holes or not _inside_sorter(sorter, p):
        return False
    c, s = math.cos(math.radians(sorter.yaw)), math.sin(math.radians(sorter.yaw))
    ly = -s * (p[0] - sorter.x) + c * (p[1] - sorter.y)
    n = len(sorter.holes)
    return int(math.floor(ly / SORTER.pitch + n / 2)) == sorter.holes.index(spec.shape_name)


def _plan_sorter(scene: SceneSpec, state: StateView) -> list[Action]:
    sorter = next(o for o in scene.objects if o.kind == "sorter")
    # the shapes still to sort (hard: two), the one in the gripper first
    todo = [t for t in scene.goal.sorted_ids
            if state.held == t or not _in_own_compartment(sorter, scene.get(t), state.positions[t])]
    if not todo:
        return []
    obj = state.held if state.held in todo else todo[0]
    spec = scene.get(obj)
    _check_reachable(scene, state, todo)
    for t in todo:
        if state.held != t and _inside_sorter(sorter, state.positions[t]):
            raise NoPlan("{obj} fell into a compartment of the shape sorter that is not its own", t)
    k = sorter.holes.index(spec.shape_name)
    hx, hy = hole_centres(sorter)[k]
    acts, yaw, off, low = _holding(scene, state, obj)
    h = SHAPES[spec.shape_name].height
    # turn the held shape so it lines up with its hole (modulo the shape's symmetry)
    sym = SYMMETRY[spec.shape_name]
    want = sorter.yaw + (sorter.hole_yaws[k] if sorter.hole_yaws else 0.0)  # a hard sorter's outline is turned
    delta = 0.0 if spec.shape == "cylinder" else _wrap(want - state.yaws[obj], sym)
    yaw_place = _wrap(yaw + delta, 360.0)
    c, s = math.cos(math.radians(delta)), math.sin(math.radians(delta))
    off_r = np.array([c * off[0] - s * off[1], s * off[0] + c * off[1], off[2]])
    target = np.array([hx, hy, TABLE_TOP + SORTER.height + h / 2 + 0.015])
    tcp = _place_tcp(target, off_r)
    zt = target[2] - off_r[2]
    steps = [_act(tcp[0], tcp[1], zt + 0.05, yaw_place, False), _act(tcp[0], tcp[1], zt, yaw_place, False),
             _act(tcp[0], tcp[1], zt, yaw_place, True)]
    return _carry(scene, state, obj, acts, yaw, off, low, (sorter.id,), steps)


def _inside_sorter(sorter: ObjectSpec, p: np.ndarray) -> bool:
    c, s = math.cos(math.radians(sorter.yaw)), math.sin(math.radians(sorter.yaw))
    dx, dy = p[0] - sorter.x, p[1] - sorter.y
    lx, ly = c * dx + s * dy, -s * dx + c * dy
    return (abs(lx) < SORTER.depth / 2 and abs(ly) < SORTER.length(len(sorter.holes)) / 2
            and p[2] < TABLE_TOP + SORTER.height - SORTER.plate)


def _on_top(pa: np.ndarray, pb: np.ndarray) -> bool:
    side = 2 * CUBE_HALF
    return bool(np.linalg.norm(pa[:2] - pb[:2]) < 0.6 * side and 0.8 * side < pa[2] - pb[2] < 1.2 * side)


def _free_spot(scene: SceneSpec, state: StateView, moving: str) -> np.ndarray:
    """A table spot (x, y) at least 10 cm from every other object, as near the table's middle as possible."""
    taken = [q[:2] for o, q in state.positions.items() if o != moving]
    fixed = _fixed_obstacles(scene)
    best, best_d = None, 1e9
    for x in np.arange(0.0, 0.30, 0.02):
        for y in np.arange(-0.30, 0.301, 0.02):
            pt = np.array([x, y])
            if all(np.linalg.norm(pt - t) >= 0.10 for t in taken) and all(
                    np.hypot(x - fx, y - fy) >= r + 0.08 for fx, fy, r in fixed):
                d = float(np.hypot(x - 0.12, y))
                if d < best_d:
                    best, best_d = pt, d
    if best is None:
        raise NoPlan("there is no free place on the table to put a cube aside")
    return best


def _predict(state: StateView, obj: str, pos: np.ndarray, yaw: float, tcp: np.ndarray, tcp_yaw: float) -> StateView:
    """The state after ``obj`` was released at ``pos`` with the arm at ``tcp`` (gripper open)."""
    new_pos = dict(state.positions)
    new_pos[obj] = pos
    new_yaw = dict(state.yaws)
    new_yaw[obj] = yaw
    return replace(state, positions=new_pos, yaws=new_yaw, held=None, held_offset=None, gripper_open=True,
                   tcp=tcp, tcp_yaw=tcp_yaw, tcp_down=True)


def _plan_stack(scene: SceneSpec, state: StateView) -> list[Action]:
    order = list(scene.goal.order)
    _check_reachable(scene, state, order)
    side = 2 * CUBE_HALF
    acts: list[Action] = []
    sv = state
    for _ in range(8):  # each round puts one cube in its place (or one cube aside)
        pos = sv.positions
        base_ok = sv.held != order[0] and abs(pos[order[0]][2] - (TABLE_TOP + CUBE_HALF)) < 0.01
        done = 1 if base_ok else 0
        if base_ok:
            for below, above in zip(order[:-1], order[1:]):
                turned = scene.goal.flush and abs(_wrap(sv.yaws[above] - sv.yaws[below], 90.0)) > FLUSH_TOLERANCE
                if sv.held not in (below, above) and _on_top(pos[above], pos[below]) and not turned:
                    done += 1
                else:
                    break
        if done == len(order):
            return acts
        if sv.held is not None and (done == 0 or sv.held != order[done]):  # holding a cube that must go aside
            sv, more = _put_aside(scene, sv, sv.held)
            acts += more
            continue
        # something on top of the cube that must receive the next one (or of the base to be moved)?
        receiver = order[done - 1] if done > 0 else order[0]
        blocker = next((o for o, q in pos.items() if o != receiver and o != sv.held and _on_top(q, pos[receiver])),
                       None)
        if blocker is not None and (done == 0 or blocker != order[done]):
            sv, more = _put_aside(scene, sv, blocker)
            acts += more
            continue
        if done == 0:  # the base is not on the table: put it there
            sv, more = _put_aside(scene, sv, order[0])
            acts += more
            continue
        below, above = order[done - 1], order[done]
        a, yaw, off, low = _holding(scene, sv, above)
        pb = sv.positions[below]
        target = np.array([pb[0], pb[1], pb[2] + side + 0.006])
        tcp = _place_tcp(target, off)
        # turn the held cube to line up with the one below (cubes repeat every 90 degrees)
        yaw_place = yaw + _wrap(sv.yaws[below] - sv.yaws[above], 90.0)
        zt = target[2] - off[2]
        steps = [_act(tcp[0], tcp[1], zt + 0.06, yaw_place, False), _act(tcp[0], tcp[1], zt, yaw_place, False),
                 _act(tcp[0], tcp[1], zt, yaw_place, True)]
        acts += _carry(scene, sv, above, a, yaw, off, False, (), steps)
        sv = _predict(sv, above, np.array([pb[0], pb[1], pb[2] + side]), sv.yaws[below], np.array([tcp[0], tcp[1], zt]),
                      yaw_place)
    raise NoPlan("the cubes cannot be sorted into the tower")


def _put_aside(scene: SceneSpec, sv: StateView, obj: str) -> tuple[StateView, list[Action]]:
    """Carry ``obj`` to a free place on the table and release it there."""
    a, yaw, off, low = _holding(scene, sv, obj)
    spot = _free_spot(scene, sv, obj)
    z_obj = _resting_z(scene, obj) + 0.006
    tcp = _place_tcp(np.array([spot[0], spot[1], z_obj]), off)
    zt = z_obj - off[2]
    steps = [_act(tcp[0], tcp[1], zt + 0.06, yaw, False), _act(tcp[0], tcp[1], zt, yaw, False),
             _act(tcp[0], tcp[1], zt, yaw, True)]
    acts = _carry(scene, sv, obj, a, yaw, off, False, (), steps)
    return _predict(sv, obj, np.array([spot[0], spot[1], z_obj - 0.006]), sv.yaws[obj], np.array([tcp[0], tcp[1], zt]),
                    yaw), acts


def _plan_wipe(scene: SceneSpec, state: StateView) -> list[Action]:
    g = scene.goal
    sponge, area = g.target_id, scene.get(g.area)
    _check_reachable(scene, state, [sponge])
    acts, yaw, off, low = _holding(scene, state, sponge)
    axis, sign, start, end, l_lo, l_hi = wipe_axes(area, g.stroke)
    lateral = (l_lo + l_hi) / 2
    u0 = start - sign * 0.01
    u1 = end + sign * 0.015
    z_contact = TABLE_TOP + SPONGE.dims(scene.get(sponge))[2] / 2 + 0.002

    def point(u: float) -> np.ndarray:
        return np.array([u, lateral, z_contact]) if axis == 0 else np.array([lateral, u, z_contact])

    t0, t1 = _place_tcp(point(u0), off), _place_tcp(point(u1), off)
    zt = z_contact - off[2]
    steps = [_act(t0[0], t0[1], zt + 0.06, yaw, False), _act(t0[0], t0[1], zt, yaw, False),
             _act(t1[0], t1[1], zt, yaw, False)]
    if not acts:
        if _at(state, steps[1]):
            return steps[2:]
        if _at(state, steps[0]):
            return steps[1:]
        return steps  # (also after a stroke that did not count: start it again from above)
    return acts + steps
