"""Inverse kinematics and collision-checked paths for the Panda.

IK is damped least squares on MuJoCo's site Jacobian of the tool centre point (6-D pose error), with a
null-space pull toward a comfortable posture and joint limits enforced at every iteration. Paths are
tried in order: a straight line of the tool in Cartesian space, a straight line in joint space, and a
lift-over-and-down detour; each waypoint is checked for contacts of the arm (and of a held object) with
the table and the other objects. The arm is moved kinematically along the accepted path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from eb_scenekit.gl import import_mujoco

from eb_manipulation.robot import ARM_JOINTS, FINGER_JOINTS

mujoco = import_mujoco()  # the GL backend is chosen before MuJoCo is imported

__all__ = ["Arm", "Blocker", "PathResult", "rotvec_between"]

ROBOT_TOL = 0.002
"""Robot geoms may touch things by up to 2 mm without it counting as a collision."""
HELD_TOL = 0.010
"""A held object may press into the table or other objects by up to 1 cm (a sponge is soft; the
simulation settles small overlaps after release)."""
WORSEN_TOL = 0.003
MAX_REACH = 1.02
"""No tool pose farther than this from the shoulder (joint 2) is reachable (sampled maximum: 0.98 m)."""
"""A contact present at the start of a motion is tolerated while it gets no deeper than this."""


def rotvec_between(R_cur: np.ndarray, R_goal: np.ndarray) -> np.ndarray:
    """World-frame rotation vector that turns ``R_cur`` into ``R_goal``."""
    Re = R_goal @ R_cur.T
    cos = max(-1.0, min(1.0, (np.trace(Re) - 1.0) / 2.0))
    angle = math.acos(cos)
    if angle < 1e-9:
        return np.zeros(3)
    if math.pi - angle < 1e-6:
        # 180 degrees: axis from the diagonal
        axis = np.sqrt(np.maximum((np.diag(Re) + 1.0) / 2.0, 0.0))
        k = int(np.argmax(axis))
        col = Re[:, k] + np.eye(3)[:, k]
        axis = col / np.linalg.norm(col)
        return axis * angle
    axis = np.array([Re[2, 1] - Re[1, 2], Re[0, 2] - Re[2, 0], Re[1, 0] - Re[0, 1]]) / (2.0 * math.sin(angle))
    return axis * angle


def _as_slice(idx: np.ndarray) -> slice | np.ndarray:
    """``slice(a, b)`` for consecutive indices a..b-1, else the index array itself."""
    if len(idx) and np.array_equal(idx, np.arange(idx[0], idx[0] + len(idx))):
        return slice(int(idx[0]), int(idx[0]) + len(idx))
    return idx


def _slerp_R(R0: np.ndarray, R1: np.ndarray, t: float) -> np.ndarray:
    v = rotvec_between(R0, R1) * t
    angle = float(np.linalg.norm(v))
    if angle < 1e-12:
        return R0.copy()
    k = v / angle
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    Rk = np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K
    return Rk @ R0


@dataclass(frozen=True)
class Blocker:
    """What a path would hit: ``"table"`` or an object id, and how deep (m)."""

    what: str
    depth: float
    by_held: bool = False


@dataclass
class PathResult:
    ok: bool
    path: list[np.ndarray] = field(default_factory=list)
    """Joint vectors from start (excluded) to goal (included)."""
    reason: str = ""
    """``unreachable`` | ``goal_collision`` | ``path_collision`` when not ok."""
    blocker: Blocker | None = None


class Arm:
    """Kinematic control of the Panda inside one MuJoCo model/data pair."""

    def __init__(self, model, data, geom_owner: dict[int, str]):
        self.m, self.d = model, data
        self.qadr = np.array([model.joint(j).qposadr[0] for j in ARM_JOINTS])
        self.dadr = np.array([model.joint(j).dofadr[0] for j in ARM_JOINTS])
        self.lo = np.array([model.joint(j).range[0] for j in ARM_JOINTS])
        self.hi = np.array([model.joint(j).range[1] for j in ARM_JOINTS])
        self.fadr = np.array([model.joint(j).qposadr[0] for j in FINGER_JOINTS])
        self.fdadr = np.array([model.joint(j).dofadr[0] for j in FINGER_JOINTS])
        self.site = model.site("tcp").id
        base = model.body("robot_base").id
        robot_bodies = {b for b in range(model.nbody) if self._descends(b, base)}
        self.robot_geoms = {g for g in range(model.ngeom) if model.geom_bodyid[g] in robot_bodies}
        left = model.body("panda0_leftfinger").id
        right = model.body("panda0_rightfinger").id
        self.left_geoms = {g for g in self.robot_geoms if model.geom_bodyid[g] == left}
        self.right_geoms = {g for g in self.robot_geoms if model.geom_bodyid[g] == right}
        self.table_geom = model.geom("table").id
        mujoco.mj_kinematics(model, data)
        self.shoulder = data.xpos[model.body("panda0_link2").id].copy()
        self.geom_owner = geom_owner
        self.rest = None  # set by the world: the comfortable posture for the null-space pull
        # one (6, nv) Jacobian whose halves mj_jacSite fills in place (no stacking per IK iteration)
        self._jac = np.zeros((6, model.nv))
        self._jacp, self._jacr = self._jac[:3], self._jac[3:]
        self._w = np.array([1.0, 1.0, 1.0, 0.77, 0.77, 0.77])  # rotation error weighs 0.6 (= 0.77^2)
        self._wcol = self._w[:, None].copy()
        self._ww = self._w * self._w
        self._damp = 0.03 ** 2
        # arm joints as slices when their qpos / dof addresses are consecutive (they are in our scenes): slice
        # reads and writes cost a fraction of fancy indexing in the IK loop
        self._qsl = _as_slice(self.qadr)
        self._dsl = _as_slice(self.dadr)
        self._fsl = _as_slice(self.fadr)
        self._fdsl = _as_slice(self.fdadr)
        # per-geom lookups for the vectorised contact filter
        self._is_robot = np.zeros(model.ngeom, dtype=bool)
        self._is_robot[list(self.robot_geoms)] = True
        owners = sorted(set(geom_owner.values()))
        self._owner_code = {o: k for k, o in enumerate(owners)}
        self._geom_owner_code = np.full(model.ngeom, -1, dtype=np.int64)
        for g, o in geom_owner.items():
            self._geom_owner_code[g] = self._owner_code[o]

    def _descends(self, b: int, ancestor: int) -> bool:
        while b != 0:
            if b == ancestor:
                return True
            b = self.m.body_parentid[b]
        return False

    # --- state -------------------------------------------------------------------------------------------
    def q(self) -> np.ndarray:
        return self.d.qpos[self._qsl].copy()

    def set_q(self, q: np.ndarray) -> None:
        self.d.qpos[self._qsl] = q
        self.d.qvel[self._dsl] = 0.0

    def fingers(self) -> float:
        return float(self.d.qpos[self.fadr[0]])

    def set_fingers(self, width: float) -> None:
        self.d.qpos[self._fsl] = width
        self.d.qvel[self._fdsl] = 0.0

    def tcp(self) -> tuple[np.ndarray, np.ndarray]:
        """Position and rotation matrix of the tool centre point (after a kinematics pass)."""
        return self.d.site_xpos[self.site].copy(), self.d.site_xmat[self.site].reshape(3, 3).copy()

    def fk(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        self.set_q(q)
        mujoco.mj_kinematics(self.m, self.d)
        return self.tcp()

    # --- inverse kinematics -----------------------------------------------------------------------------
    def ik(self, p: np.ndarray, R: np.ndarray, q0: np.ndarray, iters: int = 150,
           pos_tol: float = 1.5e-3, rot_tol: float = 0.015, null_gain: float = 0.05) -> np.ndarray | None:
        """Joint vector reaching pose (p, R) starting from ``q0``, or None. Leaves ``d.qpos`` at the result.

        Each iteration is one damped-least-squares step with a null-space pull toward the rest posture,
        ``dq = Jw^T (Jw Jw^T + damp I)^-1 (e - g Jw (rest - q)) + g (rest - q)`` (the same step as
        ``Jw^T A e + g (I - Jw^T A Jw)(rest - q)``), solved by a 6 x 6 Cholesky factorisation in place.
        """
        m, d = self.m, self.d
        lo, hi = self.lo, self.hi
        q = np.minimum(np.maximum(np.asarray(q0, dtype=float), lo), hi)
        rest = self.rest if self.rest is not None else q
        q_goal, q_cur, q_err, er = np.empty(4), np.empty(4), np.empty(4), np.empty(3)
        mujoco.mju_mat2Quat(q_goal, np.ascontiguousarray(R, dtype=float).ravel())
        qpos, qsl, dsl, site = d.qpos, self._qsl, self._dsl, self.site
        site_pos, site_mat = d.site_xpos[site], d.site_xmat[site]  # views into MjData, refreshed by mj_kinematics
        jac, jacp, jacr, wcol, ww, damp = self._jac, self._jacp, self._jacr, self._wcol, self._ww, self._damp
        e = np.empty(6)
        M = np.empty((6, 6))
        y = np.empty(6)
        diag = np.arange(6)
        kinematics, com_pos, jac_site = mujoco.mj_kinematics, mujoco.mj_comPos, mujoco.mj_jacSite
        mat2quat, neg_quat, mul_quat, quat2vel = mujoco.mju_mat2Quat, mujoco.mju_negQuat, mujoco.mju_mulQuat, \
            mujoco.mju_quat2Vel
        chol_factor, chol_solve = mujoco.mju_cholFactor, mujoco.mju_cholSolve
        checkpoint = np.inf
        d.qvel[dsl] = 0.0
        for it in range(iters):
            qpos[qsl] = q
            kinematics(m, d)
            ep = p - site_pos
            mat2quat(q_cur, site_mat)
            neg_quat(q_cur, q_cur)
            mul_quat(q_err, q_goal, q_cur)
            if q_err[0] < 0:
                q_err *= -1.0
            quat2vel(er, q_err, 1.0)
            pe, re = math.sqrt(ep @ ep), math.sqrt(er @ er)
            if pe < pos_tol and re < rot_tol:
                return q
            if it % 12 == 11:  # give up on a seed that has stopped making progress
                err = pe + 0.1 * re
                if err > 0.85 * checkpoint and err > 0.02:
                    return None
                checkpoint = err
            com_pos(m, d)
            jac_site(m, d, jacp, jacr, site)
            Jw = jac[:, dsl] * wcol
            e[:3] = ep
            e[3:] = er
            e *= ww
            dr = rest - q
            np.matmul(Jw, Jw.T, out=M)
            M[diag, diag] += damp
            chol_factor(M, 0.0)
            chol_solve(y, M, e - null_gain * (Jw @ dr))
            dq = Jw.T @ y + null_gain * dr
            step = np.abs(dq).max()
            if step > 0.25:
                dq *= 0.25 / step
            q = np.minimum(np.maximum(q + dq, lo), hi)
        return None

    def solve(self, p: np.ndarray, R: np.ndarray, q_start: np.ndarray) -> np.ndarray | None:
        """IK from several seeds; the converged solution closest to ``q_start``."""
        if np.linalg.norm(p - self.shoulder) > MAX_REACH:
            return None
        seeds = [q_start]
        if self.rest is not None:
            r = self.rest.copy()
            base = self.m.body("robot_base").pos
            r[0] = float(np.clip(math.atan2(p[1] - base[1], p[0] - base[0]), self.lo[0], self.hi[0]))
            seeds += [r, self.rest]
            for d7 in (-1.5, 1.5):
                s = r.copy()
                s[6] = float(np.clip(s[6] + d7, self.lo[6], self.hi[6]))
                seeds.append(s)
        best = None
        for s in seeds:
            q = self.ik(p, R, s)
            if q is not None:
                if best is None or np.linalg.norm(q - q_start) < np.linalg.norm(best - q_start):
                    best = q
                if np.max(np.abs(q - q_start)) < 1.2:
                    break
        if best is None:
            # poses close to the base need folded postures: a fixed set of scattered seeds (deterministic)
            for s in self._extra_seeds():
                q = self.ik(p, R, s, iters=120)
                if q is not None:
                    return q
        return best

    def _extra_seeds(self) -> np.ndarray:
        if not hasattr(self, "_seeds"):
            rng = np.random.default_rng(20240607)
            self._seeds = rng.uniform(self.lo + 0.1, self.hi - 0.1, size=(5, 7))
        return self._seeds

    # --- collisions -------------------------------------------------------------------------------------
    def contacts(self, held: str | None) -> dict[tuple[int, int], float]:
        """Relevant contacts at the current configuration: (robot-or-held geom, other geom) -> distance.

        Contacts of the robot or the held object with anything else, keyed robot/held side first; contacts within
        the robot and between the robot and the held object are left out. Filtered with numpy over MuJoCo's
        contact arrays; the dict keeps the contact order (the first deepest contact names the blocker).
        """
        mujoco.mj_kinematics(self.m, self.d)
        mujoco.mj_collision(self.m, self.d)
        out: dict[tuple[int, int], float] = {}
        if self.d.ncon == 0:
            return out
        con = self.d.contact
        g1, g2, dist = con.geom1, con.geom2, con.dist
        a_robot, b_robot = self._is_robot[g1], self._is_robot[g2]
        code = self._owner_code.get(held, -2) if held is not None else -2
        if code >= 0:
            a_held, b_held = self._geom_owner_code[g1] == code, self._geom_owner_code[g2] == code
            a_self, b_self = a_robot | a_held, b_robot | b_held
            keep = ~((a_robot & b_held) | (b_robot & a_held) | (a_robot & b_robot)) & (a_self | b_self)
        else:
            a_self, b_self = a_robot, b_robot
            keep = (a_robot ^ b_robot)
        for i in np.flatnonzero(keep).tolist():
            key = (int(g1[i]), int(g2[i])) if a_self[i] else (int(g2[i]), int(g1[i]))
            out[key] = min(out.get(key, 1.0), float(dist[i]))
        return out

    def blocker(self, contacts: dict[tuple[int, int], float], start: dict[tuple[int, int], float],
                held: str | None) -> Blocker | None:
        """The deepest contact that counts as a collision, if any."""
        worst: Blocker | None = None
        for (g_self, g_other), dist in contacts.items():
            is_held = g_self not in self.robot_geoms
            tol = HELD_TOL if is_held else ROBOT_TOL
            if dist > -tol:
                continue
            if (g_self, g_other) in start and dist >= start[(g_self, g_other)] - WORSEN_TOL:
                continue
            what = "table" if g_other == self.table_geom else self.geom_owner.get(g_other, "scene")
            if worst is None or -dist > worst.depth:
                worst = Blocker(what=what, depth=-dist, by_held=is_held)
        return worst

    # --- paths ------------------------------------------------------------------------------------------
    def plan(self, p_goal: np.ndarray, R_goal: np.ndarray, held: str | None, move_held) -> PathResult:
        """A collision-free joint path from the current configuration to the pose, or why there is none.

        ``move_held(q)`` places a held object for configuration q (no-op when nothing is held).
        """
        q0 = self.q()
        start = self._contacts_at(q0, held, move_held)
        q_goal = self.solve(p_goal, R_goal, q0)
        if q_goal is None:
            self._restore(q0, move_held)
            return PathResult(ok=False, reason="unreachable")
        b = self.blocker(self._contacts_at(q_goal, held, move_held), start, held)
        if b is not None:
            self._restore(q0, move_held)
            return PathResult(ok=False, reason="goal_collision", blocker=b)
        p0, R0 = self.fk(q0)
        first_blocker: Blocker | None = None
        # 1) straight line of the tool
        path, b = self._cartesian(q0, [(p0, R0), (p_goal, R_goal)], held, move_held, start)
        if path is not None and np.max(np.abs(path[-1] - q_goal)) > 0.5:
            path = path + self._joint_line(path[-1], q_goal)
        if path is None:
            first_blocker = first_blocker or b
            # 2) straight line in joint space
            path, b = self._check(self._joint_line(q0, q_goal), held, move_held, start)
        if path is None:
            first_blocker = first_blocker or b
            # 3) lift, travel, lower
            z_lift = min(max(p0[2], p_goal[2]) + 0.15, 1.35)
            waypoints = [(p0, R0), (np.array([p0[0], p0[1], z_lift]), R0),
                         (np.array([p_goal[0], p_goal[1], z_lift]), R_goal), (p_goal, R_goal)]
            path, b = self._cartesian(q0, waypoints, held, move_held, start)
        self._restore(q0, move_held)
        if path is None:
            return PathResult(ok=False, reason="path_collision", blocker=first_blocker or b)
        return PathResult(ok=True, path=path)

    def _restore(self, q0: np.ndarray, move_held) -> None:
        self.set_q(q0)
        move_held(q0)
        mujoco.mj_kinematics(self.m, self.d)

    def _contacts_at(self, q: np.ndarray, held, move_held) -> dict[tuple[int, int], float]:
        self.set_q(q)
        move_held(q)
        return self.contacts(held)

    def _joint_line(self, qa: np.ndarray, qb: np.ndarray) -> list[np.ndarray]:
        n = max(2, int(math.ceil(np.max(np.abs(qb - qa)) / 0.04)))
        return [qa + (qb - qa) * (k / n) for k in range(1, n + 1)]

    def _check(self, path: list[np.ndarray], held, move_held, start) -> tuple[list[np.ndarray] | None, Blocker | None]:
        for q in path:
            b = self.blocker(self._contacts_at(q, held, move_held), start, held)
            if b is not None:
                return None, b
        return path, None

    def _cartesian(self, q0: np.ndarray, poses, held, move_held, start) -> tuple[list[np.ndarray] | None, Blocker | None]:
        path: list[np.ndarray] = []
        q = q0
        for (pa, Ra), (pb, Rb) in zip(poses[:-1], poses[1:]):
            dist = float(np.linalg.norm(pb - pa))
            ang = float(np.linalg.norm(rotvec_between(Ra, Rb)))
            n = max(1, int(math.ceil(max(dist / 0.012, ang / math.radians(4.0)))))
            for k in range(1, n + 1):
                t = k / n
                p = pa + (pb - pa) * t
                R = _slerp_R(Ra, Rb, t)
                qn = self.ik(p, R, q, iters=40)
                if qn is None:
                    qn = self.ik(p, R, q, iters=250, null_gain=0.0)
                if qn is None or np.max(np.abs(qn - q)) > 0.35:
                    return None, None
                b = self.blocker(self._contacts_at(qn, held, move_held), start, held)
                if b is not None:
                    return None, b
                path.append(qn)
                q = qn
        return path, None
