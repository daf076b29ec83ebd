"""The simulated tabletop: moves the arm, grasps and releases, lets objects settle, checks success.

The arm is driven kinematically along collision-checked paths (see :mod:`eb_manipulation.kinematics`);
everything else is MuJoCo physics. A grasp is a contact rule: while the gripper closes, an object is
attached to the hand only when the left *and* the right finger touch it; a single finger that touches a
loose object pushes it sideways (as a real parallel gripper centres an object). Released objects fall
and settle under gravity and friction before the next observation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from eb_scenekit.gl import import_mujoco
from eb_scenekit.scene import compile_model

from eb_manipulation.actions import bin_to_angle, bin_to_pos, euler_to_matrix
from eb_manipulation.kinematics import Arm, Blocker
from eb_manipulation.robot import FINGER_OPEN, HOME_QPOS, REST_QPOS
from eb_manipulation.scene import (
    CONTAINER,
    DIRECTION_STEP,
    SHAPE_BITS,
    SORTER,
    SPONGE,
    TABLE_TOP,
    build_scene,
    hole_centres,
)
from eb_manipulation.shapes import CUBE_HALF, SHAPES, SYMMETRY
from eb_manipulation.spec import FIT_TOLERANCE, FLUSH_TOLERANCE, ObjectSpec, SceneSpec

mujoco = import_mujoco()  # the GL backend is chosen before MuJoCo is imported

__all__ = ["ActionOutcome", "World", "WorldObject"]

CONTACT_HEIGHT = 0.012
"""The sponge wipes the table while its bottom is at most this far above the table top (m)."""
KEEP_MOVE = 0.02
"""A loose object to be left alone counts as disturbed once it moved more than this from its start (m)."""
SETTLE_MAX_STEPS = 900
SETTLE_MIN_STEPS = 50


@dataclass(frozen=True)
class WorldObject:
    """An entry of the object list the agent sees (shapes, sponge, containers, sorter holes, areas)."""

    key: str
    """Object id, or ``<sorter id>_hole<k>`` for a sorter hole."""
    kind: str
    description: str
    """Plain description, e.g. ``red star`` or ``star-shaped hole of the shape sorter``."""
    spec_id: str
    """The scene object it belongs to."""


@dataclass
class ActionOutcome:
    ok: bool
    feedback: str
    """Our wording; object references use ``{key}`` placeholders resolved by the env (``object 3``)."""
    refs: dict[str, str] = field(default_factory=dict)
    failure: str | None = None
    """The core's failure label (see :data:`FAILURES`): set when ``ok`` is False, and also on a successful close
    that holds nothing (``grasp``: the original counts that action as executed, so it stays a success)."""
    grasped: str | None = None
    """The object this action's closing gripper took hold of, if any."""


FAILURES: dict[str, str] = {
    "invalid": "affordance",  # a value outside the action space: the arm does not afford that pose / command
    "unreachable": "precondition",  # no IK solution for that position and orientation
    "goal_collision": "collision",  # the goal pose itself is inside the table or an object
    "path_collision": "collision",  # no collision-free path to the goal pose
    "empty_grasp": "grasp",  # the gripper closed but holds nothing
}
"""Why an action fails -> the core's ``StepResult.info["failure"]`` (README: Error labels and distance)."""


class World:
    """One task's world. Create it with a :class:`SceneSpec`; call :meth:`execute` with 7-D actions."""

    def __init__(self, scene: SceneSpec, resolution: int = 500, render_meshes: bool = True):
        self.scene = scene
        built = build_scene(scene, resolution=resolution, visual=render_meshes)
        self.scene_xml = built.xml
        """The model's MJCF: names the scene for caches of its compile and of its first images."""
        self.model = compile_model(built.xml, built.assets)  # a copy of a recent compile of the same scene
        self.data = mujoco.MjData(self.model)
        m = self.model
        self.geom_owner: dict[int, str] = {}
        for g in range(m.ngeom):
            name = m.geom(g).name
            if "#" in name:
                self.geom_owner[g] = name.split("#")[0]
        self.free_objects = list(built.free_objects)
        self._free_qadr = {o: m.joint(f"{o}:joint").qposadr[0] for o in self.free_objects}
        self._free_dadr = {o: m.joint(f"{o}:joint").dofadr[0] for o in self.free_objects}
        self._free_geoms = {o: {g for g, own in self.geom_owner.items() if own == o} for o in self.free_objects}
        self._contype = {g: int(m.geom_contype[g]) for gs in self._free_geoms.values() for g in gs}
        self._turned = [o for o in scene.objects if o.kind == "sorter" and o.hole_yaws]
        self.arm = Arm(m, self.data, self.geom_owner)
        self.arm.rest = np.array(REST_QPOS)
        self.held: str | None = None
        self._held_rel: tuple[np.ndarray, np.ndarray] | None = None  # object pose in the TCP frame
        self.gripper_open = True
        self.strokes: list[list[tuple[float, float]]] = []
        """Sponge paths on the table: runs of (x, y) samples while held and touching the table."""
        self._stroke_open = False
        self.wiped_fraction = 0.0
        self.disturbed: str | None = None
        """The first of the goal's ``keep_still`` objects that was disturbed, or the area to wipe when the sponge
        moved over it against its arrow (the task can then not succeed)."""
        self._start: dict[str, np.ndarray] = {}
        self.objects = self._list_objects()
        self.reset_state()

    # --- set-up -----------------------------------------------------------------------------------------
    def reset_state(self) -> None:
        mujoco.mj_resetData(self.model, self.data)
        for g, bits in self._contype.items():
            self.model.geom_contype[g] = bits
        self.arm.set_q(np.array(HOME_QPOS))
        self.arm.set_fingers(FINGER_OPEN)
        self.held, self._held_rel, self.gripper_open = None, None, True
        self.strokes, self._stroke_open, self.wiped_fraction = [], False, 0.0
        self._way_ref: tuple[float, float] | None = None
        self._set_area_alpha()
        mujoco.mj_forward(self.model, self.data)
        self.settle()
        self.disturbed = None
        self._start = {o: self.body_pos(o) for o in self.free_objects}

    def _list_objects(self) -> list[WorldObject]:
        out: list[WorldObject] = []
        for o in self.scene.objects:
            if o.kind == "shape":
                out.append(WorldObject(o.id, "shape", f"{o.colour} {o.shape}", o.id))
            elif o.kind == "container":
                out.append(WorldObject(o.id, "container", f"{o.colour} container", o.id))
            elif o.kind == "sponge":
                out.append(WorldObject(o.id, "sponge", "sponge", o.id))
            elif o.kind == "area":
                out.append(WorldObject(o.id, "area", f"{o.colour} marked area", o.id))
            elif o.kind == "sorter":
                for k, shape in enumerate(o.holes):
                    out.append(WorldObject(f"{o.id}_hole{k}", "hole", f"{_hole_name(shape)} hole of the shape sorter",
                                           o.id))
        return out

    # --- geometry queries -------------------------------------------------------------------------------
    def body_pos(self, obj_id: str) -> np.ndarray:
        return self.data.body(obj_id).xpos.copy()

    def body_mat(self, obj_id: str) -> np.ndarray:
        return self.data.body(obj_id).xmat.reshape(3, 3).copy()

    def reference_point(self, key: str) -> np.ndarray:
        """The point the object list reports for ``key`` (see README: centres, rims, hole centres)."""
        for wo in self.objects:
            if wo.key == key:
                spec = self.scene.get(wo.spec_id)
                if wo.kind in ("shape", "sponge"):
                    return self.body_pos(key)
                if wo.kind == "container":
                    return np.array([spec.x, spec.y, TABLE_TOP + CONTAINER.height])
                if wo.kind == "area":
                    return np.array([spec.x, spec.y, TABLE_TOP])
                if wo.kind == "hole":
                    k = int(key.rsplit("_hole", 1)[1])
                    hx, hy = hole_centres(spec)[k]
                    return np.array([hx, hy, TABLE_TOP + SORTER.height])
        raise KeyError(key)

    def yaw_of(self, obj_id: str) -> float:
        """Current yaw (degrees) of a free object about the vertical."""
        R = self.body_mat(obj_id)
        return math.degrees(math.atan2(R[1, 0], R[0, 0]))

    # --- actions ----------------------------------------------------------------------------------------
    def execute(self, action: tuple[int, ...], track: bool = True) -> ActionOutcome:
        """Move to the pose of a validated 7-D action, then set the gripper, then let the world settle."""
        x, y, z = (bin_to_pos(action[i], ax) for i, ax in enumerate("xyz"))
        roll, pitch, yaw = (bin_to_angle(action[3 + i]) for i in range(3))
        want_open = bool(action[6])
        p_goal = np.array([x, y, z])
        R_goal = euler_to_matrix(roll, pitch, yaw)
        res = self.arm.plan(p_goal, R_goal, self.held, self._place_held)
        if not res.ok:
            return self._failure(res.reason, res.blocker)
        sponge_held = self.held is not None and self.held == self._sponge_id()
        wiped: list[tuple[float, float]] = []
        for q in res.path:
            self.arm.set_q(q)
            self._place_held(q)
            if track:
                touched = self._track_sponge()
                if touched is not None:
                    wiped.append(touched)
        mujoco.mj_forward(self.model, self.data)
        parts = ["The arm reached the requested pose."]
        if sponge_held and track:
            parts.append(self._wipe_note(wiped))
        refs: dict[str, str] = {}
        grasped: str | None = None
        missed = False
        if want_open and not self.gripper_open:
            released = self._open()
            if released and self._turned:
                self._fit_holes(released)
            if released:
                parts.append("The gripper opened and let go of {obj}.")
                refs["obj"] = released
            else:
                parts.append("The gripper opened.")
        elif not want_open and self.gripper_open:
            grabbed, note = self._close()
            if grabbed:
                parts.append("The gripper closed and is now holding {obj}.")
                refs["obj"] = grabbed
                grasped = grabbed
            else:
                missed = True
                parts.append("The gripper closed but is not holding anything"
                             + (f" ({note})." if note else "."))
        self._end_stroke_if_lifted()
        self.settle()
        if refs.get("obj") is not None and grasped is None and self._turned \
                and any(self.on_sorter_lid(refs["obj"], s) for s in self._turned):
            parts.append("It stayed on the lid of the shape sorter, which loses the task for good.")
        if refs.get("obj") is not None and grasped is None and self.scene.goal.flush:
            below = self._not_flush_on(refs["obj"])
            if below is not None:
                parts.append("It rests on {below}, but its sides do not line up with it: the two are not flush.")
                refs["below"] = below
        self._check_keep(grasped)
        if missed:  # executed as asked (as in the original), but the grasp it was for did not happen
            return ActionOutcome(ok=True, feedback=" ".join(parts), refs=refs, failure=FAILURES["empty_grasp"])
        return ActionOutcome(ok=True, feedback=" ".join(parts), refs=refs, grasped=grasped)

    def _failure(self, reason: str, blocker: Blocker | None) -> ActionOutcome:
        if reason == "unreachable":
            return ActionOutcome(False, "The action failed: the arm cannot reach that position with that gripper "
                                        "orientation (no inverse-kinematics solution). The arm did not move.",
                                 failure=FAILURES["unreachable"])
        refs: dict[str, str] = {}
        if blocker is None:
            what = "an obstacle"
        elif blocker.what == "table":
            what = "the table"
        else:
            what = "{obj}"
            refs["obj"] = blocker.what
        who = "the object in the gripper" if blocker is not None and blocker.by_held else "the arm"
        if reason == "goal_collision":
            msg = f"The action failed: at that pose {who} would be inside {what}. The arm did not move."
        else:
            msg = f"The action failed: no collision-free path was found, {who} would hit {what}. The arm did not move."
        return ActionOutcome(False, msg, refs, failure=FAILURES.get(reason, "collision"))

    # --- held objects -----------------------------------------------------------------------------------
    def _tcp_pose(self) -> tuple[np.ndarray, np.ndarray]:
        return self.arm.tcp()

    def _place_held(self, q: np.ndarray) -> None:
        if self.held is None or self._held_rel is None:
            return
        mujoco.mj_kinematics(self.model, self.data)
        p, R = self._tcp_pose()
        rp, rR = self._held_rel
        self._set_free_pose(self.held, p + R @ rp, R @ rR)

    def _set_free_pose(self, obj: str, pos: np.ndarray, R: np.ndarray) -> None:
        a = self._free_qadr[obj]
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, R.ravel())
        self.data.qpos[a:a + 3] = pos
        self.data.qpos[a + 3:a + 7] = quat
        d = self._free_dadr[obj]
        self.data.qvel[d:d + 6] = 0.0

    def _finger_contacts(self) -> tuple[dict[str, float], dict[str, float], bool]:
        """Objects touched by the left and right finger (object id -> depth) and whether a static thing blocks."""
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_collision(self.model, self.data)
        left: dict[str, float] = {}
        right: dict[str, float] = {}
        blocked = False
        for i in range(self.data.ncon):
            c = self.data.contact[i]
            g1, g2 = int(c.geom1), int(c.geom2)
            for gf, go in ((g1, g2), (g2, g1)):
                side = left if gf in self.arm.left_geoms else right if gf in self.arm.right_geoms else None
                if side is None or go in self.arm.robot_geoms:
                    continue
                owner = self.geom_owner.get(go)
                if owner in self._free_geoms:
                    side[owner] = max(side.get(owner, 0.0), -float(c.dist))
                elif float(c.dist) < -0.002:
                    blocked = True
        return left, right, blocked

    def _close(self) -> tuple[str | None, str]:
        self.gripper_open = False
        w = self.arm.fingers()
        pushed: dict[str, float] = {}
        note = ""
        while w > 0.0:
            w = max(0.0, w - 0.0015)
            self.arm.set_fingers(w)
            left, right, blocked = self._finger_contacts()
            both = [o for o in left if o in right]
            if both:
                obj = max(both, key=lambda o: left[o] + right[o])
                self._attach(obj)
                return obj, ""
            if blocked:
                self.arm.set_fingers(w + 0.0015)
                note = "the fingers are blocked"
                break
            # a single finger pressing on a loose object pushes it toward the other finger
            for side, sign in ((left, 1.0), (right, -1.0)):
                for obj, depth in side.items():
                    if depth <= 0.0005:
                        continue
                    if pushed.get(obj, 0.0) + depth > 0.03:
                        continue
                    pushed[obj] = pushed.get(obj, 0.0) + depth
                    self._push(obj, sign * depth)
        return None, note

    def _push(self, obj: str, amount: float) -> None:
        """Slide a loose object along the fingers' closing axis (left finger pushes toward -y_tcp)."""
        _, R = self._tcp_pose()
        axis = R[:, 1]
        a = self._free_qadr[obj]
        # left finger sits on +y_tcp and closes toward -y_tcp
        self.data.qpos[a:a + 3] -= axis * amount

    def _attach(self, obj: str) -> None:
        mujoco.mj_kinematics(self.model, self.data)
        p, R = self._tcp_pose()
        op, oR = self.body_pos(obj), self.body_mat(obj)
        self.held = obj
        self._held_rel = (R.T @ (op - p), R.T @ oR)

    def turned_to_fit(self, obj: str) -> bool:
        """``obj`` is turned to match the outline of its own hole on every hard sorter (``hole_yaws``) that has one
        (within :data:`FIT_TOLERANCE` degrees, modulo the shape's symmetry)."""
        spec = self.scene.get(obj)
        if spec.kind != "shape" or spec.shape is None or spec.shape == "cylinder":
            return True
        for sorter in self._turned:
            if spec.shape in sorter.holes:
                want = sorter.yaw + sorter.hole_yaws[sorter.holes.index(spec.shape)]
                sym = SYMMETRY[spec.shape]
                if abs((self.yaw_of(obj) - want + sym / 2) % sym - sym / 2) > FIT_TOLERANCE:
                    return False
        return True

    def _fit_holes(self, obj: str) -> None:
        """On release: a shape turned away from its hole's outline is kept out of every hole (its geoms collide with
        every hole's plate) until it is grasped again; one that fits passes its own hole as usual."""
        spec = self.scene.get(obj)
        fits = self.turned_to_fit(obj)
        blocked = sum(SHAPE_BITS.values()) & ~SHAPE_BITS.get(spec.shape or "", 0)
        for g in self._free_geoms[obj]:
            base = self._contype[g]
            self.model.geom_contype[g] = base if fits or not base & SHAPE_BITS.get(spec.shape or "", 0) \
                else (base | blocked)

    def _open(self) -> str | None:
        self.gripper_open = True
        released = self.held
        self.held, self._held_rel = None, None
        self._stroke_open = False
        self.arm.set_fingers(FINGER_OPEN)
        mujoco.mj_kinematics(self.model, self.data)
        return released

    # --- physics ----------------------------------------------------------------------------------------
    def settle(self) -> None:
        """Step physics until loose objects rest; the arm and a held object stay where they are.

        Every 25 steps the loose objects' poses are compared with the previous check; the world is at
        rest when none moved more than 0.5 mm or turned more than about 1 degree.
        """
        m, d = self.model, self.data
        q = self.arm.q()
        fw = self.arm.fingers()
        loose = [self._free_qadr[o] for o in self.free_objects if o != self.held]
        last = np.concatenate([d.qpos[a:a + 7] for a in loose]) if loose else np.zeros(0)
        for step in range(1, SETTLE_MAX_STEPS + 1):
            mujoco.mj_step(m, d)
            self.arm.set_q(q)
            self.arm.set_fingers(fw)
            if self.held is not None:
                self._place_held(q)
            if step % 25 == 0 and step >= SETTLE_MIN_STEPS:
                now = np.concatenate([d.qpos[a:a + 7] for a in loose]) if loose else np.zeros(0)
                diff = np.abs(now - last).reshape(-1, 7) if loose else np.zeros((0, 7))
                last = now
                if diff.size == 0 or (diff[:, :3].max() < 5e-4 and diff[:, 3:].max() < 0.01):
                    break
        mujoco.mj_forward(m, d)

    # --- sponge tracking --------------------------------------------------------------------------------
    def _sponge_id(self) -> str | None:
        for o in self.scene.objects:
            if o.kind == "sponge":
                return o.id
        return None

    def _track_sponge(self) -> tuple[float, float] | None:
        """Record the sponge's path while it is held and touches the table; returns the point it wiped, if any."""
        sid = self._sponge_id()
        if sid is None or self.held != sid:
            return None
        mujoco.mj_kinematics(self.model, self.data)
        bottom = self._lowest_point(sid)
        point = None
        if bottom - TABLE_TOP <= CONTACT_HEIGHT:
            pos = self.body_pos(sid)
            if not self._stroke_open:
                self.strokes.append([])
                self._stroke_open = True
                self._way_ref = None
            point = (float(pos[0]), float(pos[1]))
            self.strokes[-1].append(point)
            self._check_keep_areas(point)
            self._check_stroke_way(point)
        else:
            self._stroke_open = False
        self._update_wiped()
        return point

    def _wipe_note(self, wiped: list[tuple[float, float]]) -> str:
        """Feedback on a move with the sponge in hand: where it wiped the table, or that it did not touch it.
        Says nothing about which area counts (a blind player would learn the target from it)."""
        from eb_manipulation.actions import pos_to_bin

        if not wiped:
            sid = self._sponge_id()
            gap = (self._lowest_point(sid) - TABLE_TOP) * 100 if sid is not None else 0.0
            return (f"The sponge did not touch the table during this move (its bottom ended {gap:.1f} cm above the "
                    f"table top; it wipes only while its bottom is at most {CONTACT_HEIGHT * 100:.1f} cm above it), "
                    f"so nothing was wiped.")
        (x0, y0), (x1, y1) = wiped[0], wiped[-1]
        a = f"[{pos_to_bin(x0, 'x')}, {pos_to_bin(y0, 'y')}]"
        b = f"[{pos_to_bin(x1, 'x')}, {pos_to_bin(y1, 'y')}]"
        return f"The sponge was pressed on the table and wiped from (x, y) = {a} to {b} during this move."

    # --- leave-alone conditions ---------------------------------------------------------------------------
    def _check_keep(self, grasped: str | None) -> None:
        """Mark the first disturbed ``keep_still`` object: grasped, moved by more than 2 cm, (a container) holding a
        loose object, or (the shape sorter) with a loose object left on its lid."""
        keep = self.scene.goal.keep_still
        if not keep or self.disturbed is not None:
            return
        for obj in keep:
            if obj == grasped:
                self.disturbed = obj
                return
            if obj in self._start and float(np.linalg.norm(self.body_pos(obj) - self._start[obj])) > KEEP_MOVE:
                self.disturbed = obj
                return
            spec = self.scene.get(obj)
            if spec.kind == "container" and any(self.in_container(o, obj) for o in self.free_objects
                                                if o != self.held):
                self.disturbed = obj
                return
            if spec.kind == "sorter" and any(self.on_sorter_lid(o, spec) for o in self.free_objects if o != self.held):
                self.disturbed = obj
                return

    def on_sorter_lid(self, obj: str, sorter: ObjectSpec) -> bool:
        """``obj`` rests on the sorter's lid (e.g. dropped on a hole that is not its own)."""
        p = self.body_pos(obj)
        lx, ly = _to_local(sorter, p)
        return (abs(lx) < SORTER.depth / 2 + 0.01 and abs(ly) < SORTER.length(len(sorter.holes)) / 2 + 0.01
                and p[2] > TABLE_TOP + SORTER.height)

    def _check_keep_areas(self, point: tuple[float, float]) -> None:
        if self.disturbed is not None:
            return
        for obj in self.scene.goal.keep_still:
            spec = self.scene.get(obj)
            if spec.kind == "area" and spec.size is not None:
                if abs(point[0] - spec.x) <= spec.size[0] / 2 and abs(point[1] - spec.y) <= spec.size[1] / 2:
                    self.disturbed = obj
                    return

    def _check_stroke_way(self, point: tuple[float, float]) -> None:
        """An area with an arrow (hard set): the sponge moving over it more than 45 degrees off the arrow (against
        or across it) loses the task, as the instruction says; moves shorter than 1 cm are not judged."""
        g = self.scene.goal
        if self.disturbed is not None or g.area is None:
            return
        area = self.scene.get(g.area)
        if area.arrow is None:
            return
        dx, dy = area.extent
        if abs(point[0] - area.x) > dx / 2 or abs(point[1] - area.y) > dy / 2:
            self._way_ref = None
            return
        ref = self._way_ref
        if ref is None:
            self._way_ref = point
            return
        vx, vy = point[0] - ref[0], point[1] - ref[1]
        dist = math.hypot(vx, vy)
        if dist < 0.01:
            return
        ux, uy = DIRECTION_STEP[area.arrow]
        if vx * ux + vy * uy < math.cos(math.radians(45)) * dist:
            self.disturbed = area.id
        self._way_ref = point

    def _end_stroke_if_lifted(self) -> None:
        sid = self._sponge_id()
        if sid is None or self.held != sid:
            self._stroke_open = False

    def _lowest_point(self, obj: str) -> float:
        R = self.body_mat(obj)
        p = self.body_pos(obj)
        hx, hy, hz = (s / 2 for s in SPONGE.dims(self.scene.get(obj)))
        corners = np.array([[sx * hx, sy * hy, sz * hz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        return float(np.min((corners @ R.T)[:, 2] + p[2]))

    def _update_wiped(self) -> None:
        g = self.scene.goal
        if g.family != "wipe" or g.area is None or g.direction is None:
            return
        self.wiped_fraction = max(self.wiped_fraction, wipe_coverage(self.scene.get(g.area), g.direction, self.strokes))
        self._set_area_alpha()

    def _set_area_alpha(self) -> None:
        g = self.scene.goal
        if g.family != "wipe" or g.area is None:
            return
        gid = self.model.geom(f"{g.area}#0").id
        base = self.model.geom_rgba[gid].copy()
        base[3] = 0.92 - 0.6 * self.wiped_fraction
        self.model.geom_rgba[gid] = base

    # --- success ----------------------------------------------------------------------------------------
    def evaluate(self) -> tuple[bool, float]:
        """(task solved, progress in [0, 1]) from the physical state; never solved once an object the instruction
        says to leave alone was disturbed.

        Progress is the share of the goal's conditions that hold. With leave-alone objects (the hard set) the
        leave-alone rule counts as one more condition, which holds only with all the others (as ALFRED's
        look-alike gate): a sorter with one of its two shapes through stands at 1/3, whether or not something was
        disturbed on the way; only success reaches 1. Without them (the classic set) it is the physical check's.
        """
        solved, progress = self._physical()
        if not self.scene.goal.keep_still:
            return solved, progress
        if solved and self.disturbed is None:
            return True, 1.0
        n = self._physical_conditions()
        return False, progress * n / (n + 1)

    def _physical_conditions(self) -> int:
        """How many conditions the physical check stands for: one per shape to sort, one per cube on another,
        one for a pick or a wipe."""
        g = self.scene.goal
        if g.family == "sorter":
            return len(g.sorted_ids)
        if g.family == "stack":
            return max(len(g.order) - 1, 1)
        return 1

    def _physical(self) -> tuple[bool, float]:
        """The family's physical success check alone (without the leave-alone conditions)."""
        g = self.scene.goal
        if g.family == "pick":
            ok = self.held != g.target and self.in_container(g.target_id, g.container_id)
            return ok, 1.0 if ok else 0.0
        if g.family == "sorter":
            # progress: the share of the shapes to sort already through their own holes (the hard set sorts two;
            # one through and one left on the lid is half the task, not none of it)
            through = sum(self.held != t and self.in_matching_hole(t) for t in g.sorted_ids)
            ok = through == len(g.sorted_ids)
            return ok, 1.0 if ok else through / len(g.sorted_ids)
        if g.family == "stack":
            done = self._stacked_in_order(g.order)
            n = max(len(g.order) - 1, 1)
            base_ok = self.resting_on_table(g.order[0])
            ok = base_ok and done == n
            return ok, 1.0 if ok else done / n * (1.0 if base_ok else 0.0)
        if g.family == "wipe":
            ok = self.wiped_fraction >= 1.0
            return ok, 1.0 if ok else min(self.wiped_fraction, 0.99)
        return False, 0.0

    def _not_flush_on(self, cube: str) -> str | None:
        """The cube that ``cube`` (just released) rests on when the two are turned against each other by more than
        :data:`FLUSH_TOLERANCE` (modulo 90 degrees), else None. A fact of the state, said in the feedback like a
        shape left on the sorter's lid (it tells nothing the image does not show)."""
        for other in self.free_objects:
            if other != cube and self.on_top_of(cube, other):
                off = abs((self.yaw_of(cube) - self.yaw_of(other) + 45.0) % 90.0 - 45.0)
                return other if off > FLUSH_TOLERANCE else None
        return None

    def _stacked_in_order(self, order: tuple[str, ...]) -> int:
        """How many cubes of ``order`` already sit, unheld, on the one below them, counted from the bottom."""
        done = 0
        for below, above in zip(order[:-1], order[1:]):
            if self.held in (below, above) or not self.on_top_of(above, below):
                break
            if self.scene.goal.flush and abs((self.yaw_of(above) - self.yaw_of(below) + 45.0) % 90.0 - 45.0) \
                    > FLUSH_TOLERANCE:
                break  # a flush tower (hard set): this cube is turned against the one below
            done += 1
        return done

    def distance_to_goal(self) -> float:
        """Metres still to cover before the goal holds (0.0 once it does); README: Error labels and distance.

        One object ``o`` must reach one goal point ``g``: pick -> the container's opening centre at rim height,
        sorter -> the centre of the matching hole on the lid, stack -> one cube height above the top cube
        already in place (the next cube of the order; the bottom cube's own spot on the table while it is not
        resting there), wipe -> the area's start edge and then its end edge at the height of a sponge lying
        on the table. With ``t`` the tool centre point: ``|t - o| + |o - g|`` while the gripper does not hold
        ``o``, ``|o - g|`` while it does. Wiping adds the area's length ``L`` until a stroke is under way:
        ``|t - s| + |s - S| + L`` (sponge not held), ``|s - S| + L`` (held, not wiping), ``|s - E|`` (held,
        touching the table) with ``S``/``E`` the start/end points.
        """
        if self._physical()[0]:
            return 0.0  # (also once a leave-alone object was disturbed: nothing left to move, the task is lost)
        mujoco.mj_kinematics(self.model, self.data)
        tcp = self.arm.tcp()[0]
        g = self.scene.goal
        if g.family == "wipe":
            sid = self._sponge_id()
            area = self.scene.get(g.area)
            axis, _sign, start, end, lo, hi = wipe_axes(area, g.stroke)
            assert sid is not None, "a wiping scene has a sponge"
            z = TABLE_TOP + SPONGE.dims(self.scene.get(sid))[2] / 2
            mid = (lo + hi) / 2
            S = np.array([start, mid, z]) if axis == 0 else np.array([mid, start, z])
            E = np.array([end, mid, z]) if axis == 0 else np.array([mid, end, z])
            s = self.body_pos(sid)
            if self.held == sid and self._stroke_open:
                return float(np.linalg.norm(s - E))
            rest = float(np.linalg.norm(s - S)) + abs(end - start)
            return rest if self.held == sid else float(np.linalg.norm(tcp - s)) + rest
        obj, goal = self._goal_point()
        o = self.body_pos(obj)
        to_goal = float(np.linalg.norm(o - goal))
        return to_goal if self.held == obj else float(np.linalg.norm(tcp - o)) + to_goal

    def _goal_point(self) -> tuple[str, np.ndarray]:
        """(object, point it must reach) for pick, sorter and stack (see :meth:`distance_to_goal`)."""
        g = self.scene.goal
        if g.family == "pick":
            return g.target_id, self.reference_point(g.container_id)
        if g.family == "sorter":  # the first shape not yet in its compartment (hard: two shapes)
            obj = next((t for t in g.sorted_ids if self.held == t or not self.in_matching_hole(t)), g.target_id)
            shape = self.scene.get(obj).shape
            for wo in self.objects:
                if wo.kind == "hole":
                    k = int(wo.key.rsplit("_hole", 1)[1])
                    if self.scene.get(wo.spec_id).holes[k] == shape:
                        return obj, self.reference_point(wo.key)
            raise KeyError(f"no {shape} hole")
        base = g.order[0]
        if not self.resting_on_table(base) or self.held == base:
            p = self.body_pos(base)
            return base, np.array([p[0], p[1], TABLE_TOP + CUBE_HALF])
        done = self._stacked_in_order(g.order)
        below, nxt = g.order[done], g.order[done + 1]
        return nxt, self.body_pos(below) + np.array([0.0, 0.0, 2 * CUBE_HALF])

    def is_wrong_grasp(self, obj: str, before: dict[str, np.ndarray]) -> bool:
        """Whether taking hold of ``obj`` is off-task: it is none of the task's objects (the target shape,
        the tower's cubes, the sponge) and, in stacking, did not stand on one of the tower's cubes (a cube
        that must be put aside). ``before``: object positions before the action."""
        g = self.scene.goal
        wanted = set(self.scene.target_ids) | {g.target} | set(g.order) | set(g.also)
        sid = self._sponge_id()
        if g.family == "wipe" and sid is not None:
            wanted.add(sid)
        if obj in wanted:
            return False
        if g.family == "stack":
            p = before[obj]
            for c in g.order:
                q = before[c]
                if np.linalg.norm(p[:2] - q[:2]) < 2 * CUBE_HALF and p[2] > q[2] + CUBE_HALF:
                    return False
        return True

    def in_container(self, obj: str, container: str) -> bool:
        spec = self.scene.get(container)
        p = self.body_pos(obj)
        lx, ly = _to_local(spec, p)
        half = CONTAINER.inner / 2
        return abs(lx) < half and abs(ly) < half and p[2] < TABLE_TOP + CONTAINER.height

    def in_matching_hole(self, obj: str) -> bool:
        spec_obj = self.scene.get(obj)
        p = self.body_pos(obj)
        for sorter in self.scene.objects:
            if sorter.kind != "sorter":
                continue
            lx, ly = _to_local(sorter, p)
            n = len(sorter.holes)
            if abs(lx) > SORTER.depth / 2 - SORTER.wall or p[2] > TABLE_TOP + SORTER.height - SORTER.plate:
                continue
            k = int(math.floor(ly / SORTER.pitch + n / 2))
            if 0 <= k < n and abs(ly) < SORTER.length(n) / 2 - SORTER.wall:
                return sorter.holes[k] == spec_obj.shape
        return False

    def on_top_of(self, above: str, below: str) -> bool:
        pa, pb = self.body_pos(above), self.body_pos(below)
        side = 2 * CUBE_HALF
        return bool(np.linalg.norm(pa[:2] - pb[:2]) < 0.6 * side and 0.8 * side < pa[2] - pb[2] < 1.2 * side)

    def resting_on_table(self, obj: str) -> bool:
        spec = self.scene.get(obj)
        half = SHAPES[spec.shape].height / 2 if spec.shape else CUBE_HALF
        return abs(self.body_pos(obj)[2] - (TABLE_TOP + half)) < 0.01


def _to_local(spec: ObjectSpec, p: np.ndarray) -> tuple[float, float]:
    c, s = math.cos(math.radians(spec.yaw)), math.sin(math.radians(spec.yaw))
    dx, dy = p[0] - spec.x, p[1] - spec.y
    return c * dx + s * dy, -s * dx + c * dy


def _hole_name(shape: str) -> str:
    return {"cube": "square", "cylinder": "round"}.get(shape, f"{shape}-shaped")


def wipe_axes(area: ObjectSpec, direction: str) -> tuple[int, float, float, float, float, float]:
    """(axis index, sign, start edge, end edge, lateral min, lateral max) of a wiping direction.

    Directions are as seen in the front image: right is +y, front (toward the camera) is +x.
    """
    dx, dy = area.extent
    if direction in ("left_to_right", "right_to_left"):
        axis, lo, hi, l_lo, l_hi = 1, area.y - dy / 2, area.y + dy / 2, area.x - dx / 2, area.x + dx / 2
        sign = 1.0 if direction == "left_to_right" else -1.0
    else:
        axis, lo, hi, l_lo, l_hi = 0, area.x - dx / 2, area.x + dx / 2, area.y - dy / 2, area.y + dy / 2
        sign = 1.0 if direction == "back_to_front" else -1.0
    start, end = (lo, hi) if sign > 0 else (hi, lo)
    return axis, sign, start, end, l_lo, l_hi


def wipe_coverage(area: ObjectSpec, direction: str, strokes: list[list[tuple[float, float]]]) -> float:
    """How much of the area's length one stroke covered in the named direction (1.0 = wiped).

    A stroke counts from the first sample near the start edge while it moves the right way and stays over
    the area (with a 2 cm lateral margin); it must start within 20 % of the length from the start edge and
    reach within 20 % of the end edge for a full wipe.
    """
    axis, sign, start, end, l_lo, l_hi = wipe_axes(area, direction)
    length = abs(end - start)
    best = 0.0
    for stroke in strokes:
        origin: float | None = None
        for pt in stroke:
            u, v = pt[axis], pt[1 - axis]
            if not (l_lo - 0.02 <= v <= l_hi + 0.02):
                origin = None
                continue
            progress_from_start = sign * (u - start)
            if origin is None:
                if progress_from_start <= 0.2 * length:
                    origin = progress_from_start
                continue
            if progress_from_start < origin - 0.01:  # moved backwards: restart here
                origin = progress_from_start if progress_from_start <= 0.2 * length else None
                continue
            covered = (min(progress_from_start, length) - max(origin, 0.0)) / length
            reach_end = progress_from_start >= 0.8 * length
            best = max(best, 1.0 if reach_end and covered >= 0.6 else min(covered, 0.99))
    return max(0.0, best)
