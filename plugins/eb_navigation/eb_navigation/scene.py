"""A compiled navigation scene: the MuJoCo model of a layout plus the agent's camera and marker.

The model is compiled once per scene; a step only writes the first-person camera's pose
(``model.cam_pos``/``cam_quat``) and the agent marker's mocap pose, then runs ``mj_kinematics`` and
``mj_camlight`` (microseconds).
"""

from __future__ import annotations

import math

import numpy as np

from eb_navigation._gl import mujoco
from eb_navigation.geometry import EYE_HEIGHT, AgentState
from eb_navigation.layout import Layout
from eb_navigation.mjcf import layout_to_mjcf

__all__ = ["NavScene", "camera_quat"]


def camera_quat(yaw_deg: float, tilt_deg: float) -> np.ndarray:
    """MuJoCo camera orientation (looks along its -z, up is +y) for a heading and a tilt."""
    yaw, tilt = math.radians(yaw_deg), math.radians(tilt_deg)
    fwd = np.array([math.cos(tilt) * math.cos(yaw), math.cos(tilt) * math.sin(yaw), math.sin(tilt)])
    right = np.array([math.sin(yaw), -math.cos(yaw), 0.0])
    up = np.cross(right, fwd)
    mat = np.stack([right, up, -fwd], axis=1)  # columns: camera x, y, z in world
    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, mat.reshape(-1))
    return quat


class NavScene:
    """Model + data for one layout; ``geom_object[g]`` is the index in ``layout.objects`` or -1."""

    def __init__(self, layout: Layout, resolution: int = 500) -> None:
        self.layout = layout
        self.model = mujoco.MjModel.from_xml_string(layout_to_mjcf(layout, resolution))
        self.data = mujoco.MjData(self.model)
        m = self.model
        self.cam_fp = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_CAMERA, "first_person")
        self.agent_mocap = int(m.body_mocapid[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "agent")])
        index = {o.id: k for k, o in enumerate(layout.objects)}
        body_obj = np.full(m.nbody, -1, np.int32)
        for b in range(m.nbody):
            name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b)
            if name in index:
                body_obj[b] = index[name]
        self.geom_object = body_obj[m.geom_bodyid]
        mujoco.mj_forward(m, self.data)

    def set_agent(self, s: AgentState) -> None:
        m, d = self.model, self.data
        m.cam_pos[self.cam_fp] = (s.x, s.y, EYE_HEIGHT)
        m.cam_quat[self.cam_fp] = camera_quat(s.yaw_deg, s.tilt)
        d.mocap_pos[self.agent_mocap] = (s.x, s.y, 0.0)
        half = math.radians(s.yaw_deg) / 2
        d.mocap_quat[self.agent_mocap] = (math.cos(half), 0.0, 0.0, math.sin(half))
        mujoco.mj_kinematics(m, d)
        mujoco.mj_camlight(m, d)
