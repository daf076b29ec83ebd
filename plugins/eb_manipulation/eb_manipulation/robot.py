"""The Franka Panda arm, read at run time from the installed ``gymnasium-robotics`` package.

``gymnasium-robotics`` (MIT) ships a Panda MJCF with visual and collision meshes among its Franka Kitchen
assets (the model is derived from vikashplus/franka, Apache-2.0). We do not copy those files: we locate the
installed package without importing it, parse its ``assets.xml`` and ``chain.xml`` and splice them into our
own scene XML, changing only collision bits, colours and adding a tool-centre-point site.

Why the meshes rather than capsules built from DH parameters: the kinematic chain in that MJCF *is* the
published Panda chain (same link offsets and joint limits), and a person looking at the image recognises
the real arm. Without rendering, the visual meshes are left out (``load_panda_parts(visual=False)``).
"""

from __future__ import annotations

import importlib.util
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

__all__ = [
    "ARM_JOINTS",
    "FINGER_JOINTS",
    "FINGER_OPEN",
    "HOME_QPOS",
    "REST_QPOS",
    "PandaParts",
    "TCP_OFFSET",
    "load_panda_parts",
    "panda_asset_dir",
]

INSTALL_HINT = "pip install 'gymnasium-robotics>=1.2.4,<1.5'"

#: Joint names in the MJCF, base to wrist.
ARM_JOINTS = tuple(f"robot:panda0_joint{i}" for i in range(1, 8))
FINGER_JOINTS = ("robot:panda0_finger_joint1", "robot:panda0_finger_joint2")
#: Finger slide joint value when fully open (each finger; the gripper opens 8 cm).
FINGER_OPEN = 0.04
#: Tool centre point: distance along link 7's z axis, 1.2 cm above the ends of the fingertips.
TCP_OFFSET = 0.248
#: Comfortable elbow-up posture the IK's null-space pull prefers (joint 6 of this MJCF is offset by pi/2).
REST_QPOS = (0.0, -0.6, 0.0, -2.4, 0.0, 0.25, 0.05)
#: Start pose: tool at (0.0, 0.0, 1.2) pointing straight down, fingers closing along y (roll 180, yaw 0).
HOME_QPOS = (0.0111, -0.808, -0.0072, -2.3723, -0.0044, -0.0057, 0.0069)

# Collision bits: robot geoms (type 2) touch world geoms (affinity 3) but never each other.
ROBOT_CONTYPE, ROBOT_CONAFFINITY = 2, 0
WORLD_CONTYPE, WORLD_CONAFFINITY = 1, 3

_REL = Path("envs/assets/kitchen_franka/franka_assets")


class PandaModelMissing(ImportError):
    """gymnasium-robotics (which ships the Panda model) is not installed."""


def panda_asset_dir() -> Path:
    """The ``franka_assets`` folder inside the installed gymnasium-robotics, found without importing it."""
    spec = importlib.util.find_spec("gymnasium_robotics")
    if spec is None or not spec.submodule_search_locations:
        raise PandaModelMissing(f"the Franka Panda model comes from gymnasium-robotics. Fix: {INSTALL_HINT}")
    for root in spec.submodule_search_locations:
        path = Path(root) / _REL
        if (path / "chain.xml").is_file():
            return path
    raise PandaModelMissing(f"gymnasium-robotics is installed but has no {_REL}/chain.xml. Fix: {INSTALL_HINT}")


@dataclass(frozen=True)
class PandaParts:
    """XML fragments to splice into a scene, plus the mesh files they reference."""

    defaults: str
    """``<default>`` children (the Panda classes)."""
    assets: str
    """``<mesh>`` elements."""
    body: str
    """The ``panda0_link0`` body with the whole chain."""
    mesh_files: dict[str, str]
    """Mesh name -> the absolute path of its file inside the installed package, as the ``<mesh>`` elements name
    it. MuJoCo reads the files itself: no copy of their ~8 MB is handed over on every compile, and its asset cache
    keeps them decoded for the next scene."""


def _wrist_camera() -> tuple[str, str]:
    """A camera on the side of the hand looking down past the fingertips (link-7 frame).

    The hand is turned -45 degrees about link 7's z axis; the camera sits on the hand's x side (away from the
    fingers' travel) and looks at a point just beyond the fingertips, its image x axis along the fingers.
    """
    import numpy as np

    c, s = np.cos(-np.pi / 4), np.sin(-np.pi / 4)
    hand_x, hand_y = np.array([c, s, 0.0]), np.array([-s, c, 0.0])
    pos = hand_x * 0.055 + np.array([0.0, 0.0, 0.115])
    look = np.array([0.0, 0.0, TCP_OFFSET + 0.06])
    back = pos - look
    back /= np.linalg.norm(back)  # camera z axis (MuJoCo cameras look along -z)
    x_axis = hand_y - back * float(hand_y @ back)
    x_axis /= np.linalg.norm(x_axis)
    y_axis = np.cross(back, x_axis)
    fmt = lambda v: " ".join(f"{float(t):.5f}" for t in v)  # noqa: E731
    return fmt(pos), fmt(np.concatenate([x_axis, y_axis]))


def _tostring(el: ET.Element) -> str:
    return ET.tostring(el, encoding="unicode")


@lru_cache(maxsize=2)
def load_panda_parts(visual: bool = True) -> PandaParts:
    """Parse the installed Panda MJCF and return fragments adapted to our scene.

    With ``visual=False`` the visual meshes are left out (collision geometry only): the model compiles
    several times faster, which is what the no-render mode and the task generator use.
    """
    root_dir = panda_asset_dir()
    assets_root = ET.parse(root_dir / "assets.xml").getroot()
    chain_root = ET.parse(root_dir / "chain.xml").getroot()

    # Meshes: keep names; each file is named by its absolute path in the installed package.
    mesh_files: dict[str, str] = {}
    meshes = []
    for mesh in assets_root.iter("mesh"):
        if not visual and mesh.get("name", "").endswith("_viz"):
            continue
        path = (root_dir / "meshes" / mesh.get("file", "")).resolve()
        if not path.is_file():  # pragma: no cover - depends on the third-party package
            raise PandaModelMissing(f"gymnasium-robotics is installed but lacks the Panda mesh {path}. Fix: "
                                    f"{INSTALL_HINT}")
        mesh_files[mesh.get("name", "")] = str(path)
        mesh.set("file", str(path))
        meshes.append(_tostring(mesh))

    # Defaults: the "panda" class tree; robot collision geoms get our bits, visuals a Panda white/grey.
    panda_default = None
    for d in assets_root.iter("default"):
        if d.get("class") == "panda":
            panda_default = d
            break
    if panda_default is None:  # pragma: no cover - depends on the third-party file
        raise PandaModelMissing("unexpected gymnasium-robotics Panda MJCF: no 'panda' default class")
    for d in panda_default.iter("default"):
        geom = d.find("geom")
        if geom is None:
            continue
        cls = d.get("class")
        if cls == "panda_viz":
            geom.set("rgba", "0.93 0.93 0.92 1")
            geom.set("group", "1")
        elif cls in ("panda_col", "panda_finger"):
            geom.set("contype", str(ROBOT_CONTYPE))
            geom.set("conaffinity", str(ROBOT_CONAFFINITY))
            geom.set("group", "3")
        # position actuators are not used: the arm is driven kinematically
    defaults = _tostring(panda_default)

    body = chain_root.find("body")
    if body is None:  # pragma: no cover
        raise PandaModelMissing("unexpected gymnasium-robotics Panda MJCF: no body in chain.xml")
    for site in body.iter("site"):  # the MJCF's own sites would render as grey spheres
        site.set("group", "5")
    if not visual:
        for b in body.iter("body"):
            for g in list(b.findall("geom")):
                if g.get("class") == "panda_viz":
                    b.remove(g)
    for b in body.iter("body"):
        name = b.get("name", "")
        if name == "panda0_link7":
            tcp = ET.SubElement(b, "site")
            tcp.set("name", "tcp")
            tcp.set("pos", f"0 0 {TCP_OFFSET}")
            tcp.set("euler", "0 0 -0.785398")  # y axis = the direction the fingers close along
            tcp.set("size", "0.005")
            tcp.set("rgba", "1 0 0 0")
            tcp.set("group", "5")
            cam = ET.SubElement(b, "camera")
            cam.set("name", "wrist")
            pos, xyaxes = _wrist_camera()
            cam.set("pos", pos)
            cam.set("xyaxes", xyaxes)
            cam.set("fovy", "70")
        # Dark grey joints/hand accents as on the real arm.
        if name in ("panda0_link7",):
            for g in b.findall("geom"):
                if g.get("mesh") == "hand_viz":
                    g.set("rgba", "0.25 0.25 0.27 1")
        if name in ("panda0_leftfinger", "panda0_rightfinger"):
            for g in b.findall("geom"):
                if g.get("class") == "panda_viz":
                    g.set("rgba", "0.2 0.2 0.22 1")
                else:
                    g.set("rgba", "0.3 0.3 0.3 0")
    return PandaParts(defaults=defaults, assets="\n".join(meshes), body=_tostring(body), mesh_files=mesh_files)
