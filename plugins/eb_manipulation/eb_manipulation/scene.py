"""Build the MuJoCo model of one task: a wooden table, the Panda at its back edge, the task's objects, cameras.

Geometry names carry the object they belong to (``<object id>#<k>``; sorter hole decals
``<sorter id>_hole<k>#decal``) so segmentation pixels map back to objects.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from eb_manipulation.robot import WORLD_CONAFFINITY, WORLD_CONTYPE, load_panda_parts
from eb_manipulation.shapes import COLOURS, CUBE_HALF, CYLINDER_RADIUS, SHAPES, prism_mesh, shape_outline
from eb_manipulation.spec import ObjectSpec, SceneSpec

__all__ = [
    "CONTAINER",
    "ROBOT_BASE",
    "SHAPE_BITS",
    "SORTER",
    "SPONGE",
    "TABLE_TOP",
    "BuiltScene",
    "build_scene",
    "hole_centres",
]

TABLE_TOP = 0.752
"""Height of the table top (m); the table is wooden and the robot stands on its back edge."""
TABLE_X = (-0.55, 0.78)
TABLE_Y = (-0.75, 0.75)
ROBOT_BASE = (-0.3, 0.0, TABLE_TOP)
"""Where the Panda's base stands; the red coordinate frame in the front image is drawn here."""
FRONT_CAMERA_POS = (1.0, 0.0, 1.78)
FRONT_CAMERA_TARGET = (0.06, 0.0, 0.88)
FRONT_FOVY = 42


def _front_xyaxes() -> tuple[float, ...]:
    f = np.subtract(FRONT_CAMERA_TARGET, FRONT_CAMERA_POS)
    f = f / np.linalg.norm(f)
    right = np.cross(f, (0.0, 0.0, 1.0))
    right /= np.linalg.norm(right)
    up = np.cross(right, f)
    return (*right, *up)


@dataclass(frozen=True)
class _Container:
    inner: float = 0.13  # inner side (square)
    wall: float = 0.008
    height: float = 0.06
    floor: float = 0.006


@dataclass(frozen=True)
class _Sorter:
    depth: float = 0.12  # along local x
    pitch: float = 0.10  # hole spacing along local y
    end: float = 0.012  # extra length at each end
    height: float = 0.085
    wall: float = 0.008
    plate: float = 0.008
    opening: float = 0.08  # side of the square opening under each hole (shapes are at most 6.4 cm across)

    def length(self, n: int) -> float:
        return n * self.pitch + 2 * self.end


@dataclass(frozen=True)
class _Sponge:
    size: tuple[float, float, float] = (0.062, 0.046, 0.035)

    def dims(self, obj: ObjectSpec) -> tuple[float, float, float]:
        """(x, y, z) extent of a sponge: the classic size, or the hard set's taller one (``ObjectSpec.height``)."""
        return (self.size[0], self.size[1], obj.height) if obj.height is not None else self.size


#: A collision bit of its own per loose shape (beside the world's bit): the lid of the shape sorter closes each
#: opening with an invisible plate that collides with every shape but the hole's own, so a shape passes only through
#: its matching hole (MuJoCo cannot model the star- or moon-shaped cut-outs themselves). No other geom has these
#: bits in its ``conaffinity``, so every other contact is as before.
SHAPE_BITS = {"cube": 4, "cylinder": 8, "star": 16, "moon": 32, "triangle": 64}

CONTAINER = _Container()
SORTER = _Sorter()
SPONGE = _Sponge()

_BOX_RGBA_WOOD = "0.80 0.66 0.45 1"
_SORTER_RGBA = "0.93 0.86 0.66 1"


def _rgba(colour: str, alpha: float = 1.0) -> str:
    r, g, b = COLOURS[colour]
    return f"{r:.3f} {g:.3f} {b:.3f} {alpha:g}"


def _fmt(v) -> str:
    return " ".join(f"{float(x):.6g}" for x in v)


def hole_centres(obj: ObjectSpec) -> list[tuple[float, float]]:
    """World (x, y) of each hole of a sorter, in the order of ``obj.holes``."""
    n = len(obj.holes)
    c, s = math.cos(math.radians(obj.yaw)), math.sin(math.radians(obj.yaw))
    out = []
    for k in range(n):
        ly = (k - (n - 1) / 2) * SORTER.pitch
        out.append((obj.x - s * ly, obj.y + c * ly))
    return out


@lru_cache(maxsize=1)
def _wood_png() -> bytes:
    """A procedural wood-grain texture (PNG bytes)."""
    from PIL import Image

    rng = np.random.default_rng(7)
    h, w = 256, 512
    y, x = np.mgrid[0:h, 0:w].astype(float)
    noise = rng.normal(size=(h // 8 + 2, w // 32 + 2))
    # bilinear upsample of coarse noise
    ny = np.interp(np.arange(h), np.linspace(0, h, noise.shape[0]), np.arange(noise.shape[0]))
    nx = np.interp(np.arange(w), np.linspace(0, w, noise.shape[1]), np.arange(noise.shape[1]))
    iy, ix = np.floor(ny).astype(int), np.floor(nx).astype(int)
    fy, fx = ny - iy, nx - ix
    iy1, ix1 = np.minimum(iy + 1, noise.shape[0] - 1), np.minimum(ix + 1, noise.shape[1] - 1)
    n = (noise[iy][:, ix] * (1 - fy)[:, None] * (1 - fx)[None, :] + noise[iy1][:, ix] * fy[:, None] * (1 - fx)[None, :]
         + noise[iy][:, ix1] * (1 - fy)[:, None] * fx[None, :] + noise[iy1][:, ix1] * fy[:, None] * fx[None, :])
    grain = 0.5 + 0.5 * np.sin(y * 0.9 + 0.5 * n + 0.004 * x)
    streak = rng.normal(scale=0.05, size=(h, 1)) * np.ones((1, w))
    fine = rng.normal(scale=0.025, size=(h, w))
    t = np.clip(0.35 * grain + 0.55 + streak + fine, 0, 1.2)
    base = np.array([0.62, 0.43, 0.26])
    dark = np.array([0.45, 0.29, 0.16])
    img = dark[None, None, :] + (base - dark)[None, None, :] * t[..., None]
    img = np.clip(img * 255, 0, 255).astype(np.uint8)
    buf = io.BytesIO()
    Image.fromarray(img).save(buf, format="PNG")
    return buf.getvalue()


@dataclass
class BuiltScene:
    """The model XML and the facts the world needs about it."""

    xml: str
    assets: dict[str, bytes]
    free_objects: list[str] = field(default_factory=list)
    """Ids of objects with a free joint (loose shapes, cubes, the sponge)."""


_MESH_SHAPES = tuple(s for s in SHAPES if s not in ("cube", "cylinder"))
"""Shapes drawn from meshes (cube and cylinder are MuJoCo primitives)."""


@lru_cache(maxsize=256)
def _mesh_xml(name: str, shape: str, height: float, scale: float = 1.0) -> str:
    """The ``<mesh>`` element of an extruded shape; made once per process (~10 ms each, two or three a reset)."""
    v, f = prism_mesh(shape, height)
    v = v.copy()
    v[:, :2] *= scale
    return f'<mesh name="{name}" vertex="{_fmt(v.ravel())}" face="{" ".join(str(int(i)) for i in f.ravel())}"/>'


def build_scene(scene: SceneSpec, resolution: int = 500, visual: bool = True) -> BuiltScene:
    """MJCF for ``scene`` (robot, table, objects, lights, front and wrist cameras).

    ``visual=False`` leaves out the arm's visual meshes (for simulation without images).
    """
    panda = load_panda_parts(visual)
    assets: dict[str, bytes] = {"wood.png": _wood_png()}  # the Panda's meshes are read from their files
    mesh_xml: list[str] = []
    bodies: list[str] = []
    free: list[str] = []
    shape_meshes: set[str] = set()
    if visual:
        # every rendered scene declares the same meshes in the same order, used or not (a few kB): scenes then
        # have the same render assets, so the pooled renderer draws every task with one GL context instead of
        # making one per reset (~50 ms with the Franka's meshes; eb_scenekit.pool.render_assets)
        for shape in _MESH_SHAPES:
            mesh_xml.append(_mesh_xml(f"shape_{shape}", shape, SHAPES[shape].height))
            shape_meshes.add(f"shape_{shape}")
        for shape in SHAPES:
            mesh_xml.append(_mesh_xml(f"hole_{shape}", shape, 0.001, scale=1.12))
            shape_meshes.add(f"hole_{shape}")
    world = f'contype="{WORLD_CONTYPE}" conaffinity="{WORLD_CONAFFINITY}"'

    for obj in scene.objects:
        pos_xy = (obj.x, obj.y)
        quat = (math.cos(math.radians(obj.yaw) / 2), 0.0, 0.0, math.sin(math.radians(obj.yaw) / 2))
        if obj.kind == "shape":
            info = SHAPES[obj.shape_name]
            z = TABLE_TOP + info.height / 2 + 0.001
            below = obj.on
            while below is not None:  # a cube that starts on top of others
                z += SHAPES[scene.get(below).shape_name].height + 0.001
                below = scene.get(below).on
            rgba = _rgba(obj.colour or "gray")
            shape_world = f'contype="{WORLD_CONTYPE | SHAPE_BITS[obj.shape]}" conaffinity="{WORLD_CONAFFINITY}"'
            common = f'{shape_world} rgba="{rgba}" friction="1.0 0.02 0.001" density="600" solref="0.004 1"'
            if obj.shape == "cube":
                geom = f'<geom name="{obj.id}#0" type="box" size="{CUBE_HALF} {CUBE_HALF} {CUBE_HALF}" {common}/>'
            elif obj.shape == "cylinder":
                geom = (f'<geom name="{obj.id}#0" type="cylinder" size="{CYLINDER_RADIUS} {info.height / 2}" '
                        f'{common}/>')
            else:
                mname = f"shape_{obj.shape}"
                if mname not in shape_meshes:
                    mesh_xml.append(_mesh_xml(mname, obj.shape_name, info.height))
                    shape_meshes.add(mname)
                geom = f'<geom name="{obj.id}#0" type="mesh" mesh="{mname}" {common}/>'
            bodies.append(f'<body name="{obj.id}" pos="{_fmt((*pos_xy, z))}" quat="{_fmt(quat)}">'
                          f'<freejoint name="{obj.id}:joint"/>{geom}</body>')
            free.append(obj.id)
        elif obj.kind == "sponge":
            sx, sy, sz = (s / 2 for s in SPONGE.dims(obj))
            z = TABLE_TOP + sz + 0.001
            # a yellow foam block with a green scouring layer: under it in the classic set (as it always was), on
            # top in the hard set, where the sponge is as tall as a cube and the green top is what the front
            # camera sees (what tells it from a yellow block; the rules say so). Both parts have the same density
            # and friction, so the layer's side changes nothing but the image.
            layer = 0.006 if obj.height is None else 0.009
            up = obj.height is not None
            foam_z, layer_z = (-layer / 2, sz - layer / 2) if up else (layer / 2, -sz + layer / 2)
            bodies.append(
                f'<body name="{obj.id}" pos="{_fmt((*pos_xy, z))}" quat="{_fmt(quat)}">'
                f'<freejoint name="{obj.id}:joint"/>'
                f'<geom name="{obj.id}#0" type="box" size="{sx} {sy} {sz - layer / 2}" pos="0 0 {foam_z}" {world} '
                f'rgba="0.98 0.84 0.20 1" friction="1.2 0.02 0.001" density="150" solref="0.004 1"/>'
                f'<geom name="{obj.id}#1" type="box" size="{sx} {sy} {layer / 2}" pos="0 0 {layer_z}" {world} '
                f'rgba="0.10 0.55 0.20 1" friction="1.2 0.02 0.001" density="150" solref="0.004 1"/>'
                f"</body>")
            free.append(obj.id)
        elif obj.kind == "container":
            c = CONTAINER
            half_in, w, h, fl = c.inner / 2, c.wall, c.height, c.floor
            rgba = _rgba(obj.colour or "gray")
            parts = [f'<geom name="{obj.id}#0" type="box" size="{half_in + w} {half_in + w} {fl / 2}" '
                     f'pos="0 0 {fl / 2}" rgba="{rgba}" {world}/>']
            k = 1
            for sx, sy, px, py in (
                (w / 2, half_in + w, half_in + w / 2, 0), (w / 2, half_in + w, -half_in - w / 2, 0),
                (half_in, w / 2, 0, half_in + w / 2), (half_in, w / 2, 0, -half_in - w / 2),
            ):
                parts.append(f'<geom name="{obj.id}#{k}" type="box" size="{sx} {sy} {h / 2}" '
                             f'pos="{px} {py} {h / 2}" rgba="{rgba}" {world}/>')
                k += 1
            bodies.append(f'<body name="{obj.id}" pos="{_fmt((*pos_xy, TABLE_TOP))}" quat="{_fmt(quat)}">'
                          + "".join(parts) + "</body>")
        elif obj.kind == "sorter":
            bodies.append(_sorter_body(obj, quat, world, mesh_xml, shape_meshes))
        elif obj.kind == "area":
            dx, dy = obj.extent
            bodies.append(
                f'<body name="{obj.id}" pos="{_fmt((*pos_xy, TABLE_TOP))}">'
                f'<geom name="{obj.id}#0" type="box" size="{dx / 2} {dy / 2} 0.0008" pos="0 0 0.0008" '
                f'rgba="{_rgba(obj.colour or "gray", 0.92)}" contype="0" conaffinity="0" group="1"/>'
                + (_arrow_geoms(obj) if obj.arrow else "") + "</body>")

    tx0, tx1 = TABLE_X
    ty0, ty1 = TABLE_Y
    tcx, tcy = (tx0 + tx1) / 2, (ty0 + ty1) / 2
    thx, thy = (tx1 - tx0) / 2, (ty1 - ty0) / 2
    legs = "".join(
        f'<geom name="table_leg{k}" type="box" size="0.03 0.03 {(TABLE_TOP - 0.04) / 2}" '
        f'pos="{sx * (thx - 0.06) + tcx} {sy * (thy - 0.06) + tcy} {(TABLE_TOP - 0.04) / 2}" material="wood" '
        f'contype="0" conaffinity="0"/>'
        for k, (sx, sy) in enumerate(((1, 1), (1, -1), (-1, 1), (-1, -1)))
    )
    xml = f"""<mujoco model="eb_manipulation">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="0.002" integrator="implicitfast" cone="elliptic" impratio="5">
    <flag multiccd="enable"/>
  </option>
  <visual>
    <global offwidth="{max(resolution, 64)}" offheight="{max(resolution, 64)}"/>
    <quality shadowsize="2048"/>
    <headlight ambient="0.35 0.35 0.35" diffuse="0.35 0.35 0.35" specular="0.05 0.05 0.05"/>
  </visual>
  <default>
    {panda.defaults}
  </default>
  <asset>
    {panda.assets}
    {"".join(mesh_xml)}
    <texture name="wood" type="2d" file="wood.png"/>
    <material name="wood" texture="wood" texrepeat="1 1" specular="0.15" shininess="0.3"/>
    <texture name="floor" type="2d" builtin="checker" rgb1="0.55 0.55 0.57" rgb2="0.5 0.5 0.52" width="256" height="256"/>
    <material name="floor" texture="floor" texrepeat="8 8"/>
    <texture name="sky" type="skybox" builtin="gradient" rgb1="0.82 0.85 0.9" rgb2="0.55 0.58 0.64" width="64" height="64"/>
  </asset>
  <worldbody>
    <light name="key" pos="1.2 0.6 2.6" dir="-0.45 -0.2 -1" diffuse="0.55 0.55 0.55" specular="0.1 0.1 0.1" castshadow="true"/>
    <light name="fill" pos="-0.5 -1.0 2.2" dir="0.3 0.4 -1" diffuse="0.25 0.25 0.25" specular="0 0 0" castshadow="false"/>
    <geom name="floor" type="plane" size="4 4 0.1" material="floor" contype="0" conaffinity="0"/>
    <geom name="wall" type="box" size="0.05 3 1.5" pos="-1.6 0 1.5" rgba="0.86 0.87 0.88 1" contype="0" conaffinity="0"/>
    <geom name="table" type="box" size="{thx} {thy} 0.02" pos="{tcx} {tcy} {TABLE_TOP - 0.02}" material="wood" {world}
          friction="0.8 0.02 0.001"/>
    {legs}
    <body name="robot_base" pos="{_fmt(ROBOT_BASE)}">
      {panda.body}
    </body>
    {"".join(bodies)}
    <camera name="front" pos="{_fmt(FRONT_CAMERA_POS)}" xyaxes="{_fmt(_front_xyaxes())}" fovy="{FRONT_FOVY}"/>
  </worldbody>
</mujoco>"""
    return BuiltScene(xml=xml, assets=assets, free_objects=free)


#: Unit step (dx, dy) on the table of each wiping direction (front = +x, toward the camera; right = +y).
DIRECTION_STEP = {"left_to_right": (0.0, 1.0), "right_to_left": (0.0, -1.0), "front_to_back": (-1.0, 0.0),
                  "back_to_front": (1.0, 0.0)}


def _arrow_geoms(obj: ObjectSpec) -> str:
    """An arrow printed on a marked area (hard set), pointing in ``obj.arrow``: a shaft and two head strokes of thin
    boxes (no mesh, so every scene keeps the same render assets), dark on a light area and white on a dark one."""
    ux, uy = DIRECTION_STEP[str(obj.arrow)]
    r, g, b = COLOURS[obj.colour_name]
    ink = "0.97 0.97 0.95 1" if 0.2126 * r + 0.7152 * g + 0.0722 * b < 0.35 else "0.07 0.06 0.05 1"
    long = max(obj.extent)
    tip, tail, head, half_w = 0.36 * long, -0.36 * long, 0.022, 0.0035
    parts = []

    def bar(k: int, cx: float, cy: float, half_len: float, angle: float) -> None:
        quat = (math.cos(angle / 2), 0.0, 0.0, math.sin(angle / 2))
        parts.append(f'<geom name="{obj.id}#{k}" type="box" size="{half_len:.5g} {half_w} 0.0004" '
                     f'pos="{cx:.5g} {cy:.5g} 0.0020" quat="{_fmt(quat)}" rgba="{ink}" contype="0" conaffinity="0" '
                     f'group="1"/>')

    along = math.atan2(uy, ux)
    bar(1, ux * (tip + tail) / 2, uy * (tip + tail) / 2, (tip - tail) / 2, along)
    for k, side in ((2, 1.0), (3, -1.0)):
        back = along + math.pi - side * math.radians(38)
        bar(k, ux * tip + math.cos(back) * head, uy * tip + math.sin(back) * head, head + half_w, back)
    return "".join(parts)


def _sorter_body(obj: ObjectSpec, quat, world: str, mesh_xml: list[str], shape_meshes: set[str]) -> str:
    s = SORTER
    n = len(obj.holes)
    hx = s.depth / 2
    hy = s.length(n) / 2
    H, w, p = s.height, s.wall, s.plate
    rgba = _SORTER_RGBA
    g: list[str] = []
    k = 0

    def box(size, pos, visible=True, extra=""):
        nonlocal k
        vis = f'rgba="{rgba}"' if visible else 'rgba="0 0 0 0" group="3"'
        g.append(f'<geom name="{obj.id}#{k}" type="box" size="{_fmt(size)}" pos="{_fmt(pos)}" {vis} {world} {extra}/>')
        k += 1

    box((hx, hy, 0.003), (0, 0, 0.003))  # floor
    box((w / 2, hy, H / 2), (hx - w / 2, 0, H / 2))  # front/back walls
    box((w / 2, hy, H / 2), (-hx + w / 2, 0, H / 2))
    box((hx, w / 2, H / 2), (0, hy - w / 2, H / 2))  # end walls
    box((hx, w / 2, H / 2), (0, -hy + w / 2, H / 2))
    centres = [(kk - (n - 1) / 2) * s.pitch for kk in range(n)]
    for kk in range(n - 1):  # dividers between compartments, below the plate
        box((hx - w, 0.003, (H - p) / 2), (0, (centres[kk] + centres[kk + 1]) / 2, (H - p) / 2))
    # top plate: invisible collision strips around square openings, plus one visible thin plate
    o = s.opening / 2
    zc = H - p / 2
    strip_x = (hx - o) / 2
    box((strip_x, hy, p / 2), (o + strip_x, 0, zc), visible=False)
    box((strip_x, hy, p / 2), (-o - strip_x, 0, zc), visible=False)
    edges = [-hy] + [v for c in centres for v in (c - o, c + o)] + [hy]
    for a, b in zip(edges[0::2], edges[1::2]):
        if b - a > 1e-4:
            box((o, (b - a) / 2, p / 2), (0, (a + b) / 2, zc), visible=False)
    g.append(f'<geom name="{obj.id}#{k}" type="box" size="{hx} {hy} {p / 2}" pos="0 0 {zc}" rgba="{rgba}" '
             f'contype="0" conaffinity="0" group="1"/>')
    k += 1
    for kk, shape in enumerate(obj.holes):
        mname = f"hole_{shape}"
        if mname not in shape_meshes:
            mesh_xml.append(_mesh_xml(mname, shape, 0.001, scale=1.12))
            shape_meshes.add(mname)
        turn = ""  # a hard sorter's outline turned on the lid (README: The hard set); classic XML unchanged
        if obj.hole_yaws:
            half = math.radians(obj.hole_yaws[kk]) / 2
            turn = f' quat="{_fmt((math.cos(half), 0.0, 0.0, math.sin(half)))}"'
        g.append(f'<geom name="{obj.id}_hole{kk}#decal" type="mesh" mesh="{mname}" '
                 f'pos="0 {centres[kk]} {H + 0.0006}"{turn} rgba="0.08 0.07 0.06 1" contype="0" conaffinity="0" '
                 f'group="1"/>')
    for kk, shape in enumerate(obj.holes):  # the plates that keep every other shape out of this hole
        others = sum(bit for name, bit in SHAPE_BITS.items() if name != shape)
        g.append(f'<geom name="{obj.id}#{k}" type="box" size="{_fmt((o, o, p / 2))}" pos="{_fmt((0, centres[kk], zc))}" '
                 f'rgba="0 0 0 0" group="3" contype="0" conaffinity="{others}"/>')
        k += 1
    return f'<body name="{obj.id}" pos="{obj.x} {obj.y} {TABLE_TOP}" quat="{_fmt(quat)}">' + "".join(g) + "</body>"


def sorter_hole_outline(shape: str) -> list[tuple[float, float]]:
    """Outline of a hole decal (the shape enlarged by 12 %)."""
    return shape_outline(shape, 1.12)
