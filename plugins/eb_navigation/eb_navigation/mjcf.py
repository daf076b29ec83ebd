"""Turn a :class:`~eb_navigation.layout.Layout` into an MJCF string (pure Python, no MuJoCo import).

The model has one body per object (named by its instance id, so segmentation maps pixels to objects),
the room shell in the world body, a mocap body ``agent`` (an arrow drawn only in the overhead view,
geom group 2), the ceiling in geom group 1 (hidden in the overhead view) and two cameras:
``first_person`` (moved every step by writing ``model.cam_pos``/``cam_quat``, no recompile) and
``overhead``.
"""

from __future__ import annotations

import math
from xml.sax.saxutils import quoteattr

import numpy as np

from eb_navigation.catalogue import Part, get_type
from eb_navigation.layout import WALL_HEIGHT, Layout, Placed

__all__ = ["FIRST_PERSON_FOVY", "OVERHEAD_FOVY", "layout_to_mjcf", "object_parts"]

FIRST_PERSON_FOVY = 100.0
"""Vertical field of view of the square first-person image; square, so the horizontal one is the same
(the original benchmark's camera has a 100 degree field of view)."""
OVERHEAD_FOVY = 60.0

_MATERIALS = {
    "matte": 'specular="0.05" shininess="0.05"',
    "glossy": 'specular="0.35" shininess="0.5"',
    "metal": 'specular="0.6" shininess="0.7"',
    "screen": 'specular="0.2" shininess="0.6" emission="0.9"',
    "glow": 'specular="0.1" shininess="0.1" emission="0.55"',
    "ceiling": 'specular="0" shininess="0" emission="0.4"',
    "window": 'specular="0.3" shininess="0.8" emission="0.3"',
}


def _f(v: float) -> str:
    return f"{v:.4g}"


def _vec(vals) -> str:
    return " ".join(_f(float(v)) for v in vals)


def _rgba(c) -> str:
    return _vec(c)


def object_parts(obj: Placed) -> list[Part]:
    """The parts of a placed object (its random details come from ``obj.variant``)."""
    t = get_type(obj.type)
    return t.build(obj.colour, np.random.default_rng(obj.variant))


def _frustum_name(size: tuple[float, ...]) -> str:
    return "frustum_" + "_".join(str(int(round(v * 1000))) for v in size)


def _frustum_mesh(size: tuple[float, ...], segments: int = 20) -> str:
    rb, rt, h = size
    verts = []
    for z, r in ((0.0, rb), (h, rt)):
        for k in range(segments):
            a = 2 * math.pi * k / segments
            verts += [r * math.cos(a), r * math.sin(a), z]
    return f'<mesh name="{_frustum_name(size)}" vertex="{_vec(verts)}"/>'


def _geom(part: Part, group: int = 0) -> str:
    attrs = [f'type="{"mesh" if part.shape == "frustum" else part.shape}"', f'pos="{_vec(part.pos)}"',
             f'rgba="{_rgba(part.rgba)}"', f'material="m_{part.material}"', f'group="{group}"']
    if part.shape == "frustum":
        attrs.append(f'mesh="{_frustum_name(part.size)}"')
    else:
        attrs.append(f'size="{_vec(part.size)}"')
    if part.euler is not None:
        attrs.append(f'euler="{_vec(part.euler)}"')
    return "<geom " + " ".join(attrs) + "/>"


def _wall_box(wall: int, along: float, width: float, bottom: float, height: float, W: float, D: float,
              out: float = 0.0, thick: float = 0.01) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """Centre and half sizes of a thin box flat on the inside of a wall, ``out`` metres into the room."""
    zc = bottom + height / 2
    if wall == 0:
        return (along, out + thick, zc), (width / 2, thick, height / 2)
    if wall == 2:
        return (along, D - out - thick, zc), (width / 2, thick, height / 2)
    if wall == 3:
        return (out + thick, along, zc), (thick, width / 2, height / 2)
    return (W - out - thick, along, zc), (thick, width / 2, height / 2)


def layout_to_mjcf(layout: Layout, resolution: int = 500) -> str:
    W, D, H = layout.width, layout.depth, WALL_HEIGHT
    style, c1, c2 = layout.floor
    if style == "tiles":
        floor_tex = (f'<texture name="t_floor" type="2d" builtin="checker" rgb1="{_vec(c1)}" rgb2="{_vec(c2)}" '
                     f'width="64" height="64"/>')
        repeat = (W / 0.5, D / 0.5)
    else:
        floor_tex = (f'<texture name="t_floor" type="2d" builtin="checker" rgb1="{_vec(c1)}" rgb2="{_vec(c2)}" '
                     f'width="64" height="64"/>')
        repeat = (W / 0.36, D / 2.4)

    parts_by_obj = [(o, object_parts(o)) for o in layout.objects]
    meshes = sorted({tuple(p.size) for _, parts in parts_by_obj for p in parts if p.shape == "frustum"})

    wall_rgba = (*layout.wall_rgb, 1.0)
    trim = tuple(0.8 * c for c in layout.wall_rgb) + (1.0,)
    shell = [
        f'<geom name="floor" type="box" pos="{_vec((W / 2, D / 2, -0.05))}" size="{_vec((W / 2 + 0.2, D / 2 + 0.2, 0.05))}" '
        f'material="m_floor" group="0"/>',
        f'<geom name="ceiling" type="box" pos="{_vec((W / 2, D / 2, H + 0.05))}" size="{_vec((W / 2 + 0.2, D / 2 + 0.2, 0.05))}" '
        f'rgba="0.97 0.97 0.96 1" material="m_ceiling" group="1"/>',
    ]
    for name, pos, size in (
        ("wall_south", (W / 2, -0.05, H / 2), (W / 2 + 0.1, 0.05, H / 2)),
        ("wall_north", (W / 2, D + 0.05, H / 2), (W / 2 + 0.1, 0.05, H / 2)),
        ("wall_west", (-0.05, D / 2, H / 2), (0.05, D / 2 + 0.1, H / 2)),
        ("wall_east", (W + 0.05, D / 2, H / 2), (0.05, D / 2 + 0.1, H / 2)),
    ):
        shell.append(f'<geom name="{name}" type="box" pos="{_vec(pos)}" size="{_vec(size)}" rgba="{_rgba(wall_rgba)}" '
                     f'material="m_matte" group="0"/>')
    for wall, length in ((0, W), (1, D), (2, W), (3, D)):  # skirting boards
        pos, size = _wall_box(wall, length / 2, length, 0.0, 0.08, W, D, thick=0.008)
        shell.append(f'<geom type="box" pos="{_vec(pos)}" size="{_vec(size)}" rgba="{_rgba(trim)}" material="m_matte"/>')
    for d in layout.decor:
        if d.kind == "door":
            pos, size = _wall_box(d.wall, d.along, d.width + 0.1, 0.0, d.height + 0.05, W, D, thick=0.01)
            shell.append(f'<geom type="box" pos="{_vec(pos)}" size="{_vec(size)}" rgba="0.92 0.9 0.86 1" material="m_matte"/>')
            pos, size = _wall_box(d.wall, d.along, d.width, 0.0, d.height, W, D, out=0.02, thick=0.012)
            shell.append(f'<geom type="box" pos="{_vec(pos)}" size="{_vec(size)}" rgba="{_rgba((*d.colour, 1))}" '
                         f'material="m_glossy"/>')
            knob_along = d.along + d.width * 0.38
            pos, size = _wall_box(d.wall, knob_along, 0.06, 1.0, 0.06, W, D, out=0.04, thick=0.02)
            shell.append(f'<geom type="box" pos="{_vec(pos)}" size="{_vec(size)}" rgba="0.8 0.75 0.5 1" material="m_metal"/>')
        elif d.kind == "window":
            pos, size = _wall_box(d.wall, d.along, d.width + 0.12, d.bottom - 0.06, d.height + 0.12, W, D, thick=0.012)
            shell.append(f'<geom type="box" pos="{_vec(pos)}" size="{_vec(size)}" rgba="0.96 0.96 0.96 1" material="m_glossy"/>')
            pos, size = _wall_box(d.wall, d.along, d.width, d.bottom, d.height, W, D, out=0.015, thick=0.01)
            shell.append(f'<geom type="box" pos="{_vec(pos)}" size="{_vec(size)}" rgba="{_rgba((*d.colour, 1))}" '
                         f'material="m_window"/>')
            pos, size = _wall_box(d.wall, d.along, 0.04, d.bottom, d.height, W, D, out=0.03, thick=0.01)
            shell.append(f'<geom type="box" pos="{_vec(pos)}" size="{_vec(size)}" rgba="0.96 0.96 0.96 1" material="m_glossy"/>')
        else:  # painting
            pos, size = _wall_box(d.wall, d.along, d.width + 0.06, d.bottom - 0.03, d.height + 0.06, W, D, thick=0.012)
            shell.append(f'<geom type="box" pos="{_vec(pos)}" size="{_vec(size)}" rgba="0.2 0.15 0.1 1" material="m_matte"/>')
            pos, size = _wall_box(d.wall, d.along, d.width, d.bottom, d.height, W, D, out=0.015, thick=0.008)
            shell.append(f'<geom type="box" pos="{_vec(pos)}" size="{_vec(size)}" rgba="{_rgba((*d.colour, 1))}" '
                         f'material="m_matte"/>')

    # Soft contact shadows: a dark, translucent patch under every floor-standing object (cheap stand-in
    # for real shadows, which would double the render time); in the world body so boxes ignore them.
    for obj, _parts in parts_by_obj:
        if obj.on is not None or obj.type in ("rug", "small_rug"):
            continue
        x0, y0, x1, y1 = obj.footprint
        shell.append(f'<geom type="box" pos="{_vec((obj.x, obj.y, 0.0015))}" '
                     f'size="{_vec(((x1 - x0) / 2 + 0.05, (y1 - y0) / 2 + 0.05, 0.001))}" rgba="0 0 0 0.28" '
                     f'material="m_matte" contype="0" conaffinity="0"/>')

    bodies = []
    for obj, parts in parts_by_obj:
        geoms = "".join(_geom(p) for p in parts)
        bodies.append(f'<body name={quoteattr(obj.id)} pos="{_vec((obj.x, obj.y, obj.z))}" '
                      f'euler="0 0 {obj.yaw % 4 * 90}">{geoms}</body>')

    # Overhead camera: straight down over the room centre, high enough to see the whole floor.
    half = max(W, D) / 2 + 0.7
    cam_h = half / math.tan(math.radians(OVERHEAD_FOVY / 2))
    extent = math.hypot(W, D)
    lights = []
    for k, (lx, ly) in enumerate(((W * 0.3, D * 0.3), (W * 0.7, D * 0.7))):
        lights.append(f'<light name="ceiling_{k}" pos="{_vec((lx, ly, H - 0.05))}" dir="0 0 -1" directional="false" '
                      f'diffuse="0.35 0.35 0.33" specular="0.1 0.1 0.1" attenuation="1 0 0" cutoff="90" exponent="1" '
                      f'castshadow="false"/>')
    lights.append('<light name="key" directional="true" pos="0 0 5" dir="0.55 0.35 -0.75" diffuse="0.42 0.41 0.39" '
                  'specular="0.08 0.08 0.08" castshadow="false"/>')
    lights.append('<light name="fill" directional="true" pos="0 0 5" dir="-0.45 -0.6 -0.65" diffuse="0.16 0.16 0.18" '
                  'specular="0 0 0" castshadow="false"/>')
    assets = [floor_tex,
              f'<material name="m_floor" texture="t_floor" texrepeat="{_vec(repeat)}" specular="0.15" shininess="0.3"/>']
    assets += [f'<material name="m_{n}" {a}/>' for n, a in _MATERIALS.items()]
    assets += [_frustum_mesh(m) for m in meshes]
    return f"""<mujoco model="eb_navigation_{layout.kind}_{layout.seed}">
  <compiler angle="degree"/>
  <option gravity="0 0 0"/>
  <statistic extent="{_f(extent)}" center="{_vec((W / 2, D / 2, 1.0))}"/>
  <visual>
    <global offwidth="{resolution}" offheight="{resolution}" fovy="{_f(FIRST_PERSON_FOVY)}"/>
    <headlight ambient="0.33 0.33 0.33" diffuse="0.16 0.16 0.16" specular="0.02 0.02 0.02"/>
    <map znear="0.01" zfar="40"/>
    <quality shadowsize="0"/>
  </visual>
  <asset>
    {"".join(assets)}
  </asset>
  <worldbody>
    {"".join(lights)}
    {"".join(shell)}
    {"".join(bodies)}
    <body name="agent" mocap="true" pos="{_vec((W / 2, D / 2, 0))}">
      <geom type="cylinder" pos="0 0 0.05" size="0.2 0.05" rgba="0.9 0.1 0.1 1" group="2" contype="0" conaffinity="0"/>
      <geom type="box" pos="0.22 0 0.06" size="0.14 0.05 0.05" rgba="0.9 0.1 0.1 1" group="2" contype="0" conaffinity="0"/>
      <geom type="box" pos="0.36 0 0.06" size="0.05 0.12 0.05" rgba="0.9 0.1 0.1 1" euler="0 0 45" group="2" contype="0" conaffinity="0"/>
    </body>
    <camera name="first_person" pos="{_vec((W / 2, D / 2, 1.5))}" fovy="{_f(FIRST_PERSON_FOVY)}"/>
    <camera name="overhead" pos="{_vec((W / 2, D / 2, cam_h))}" xyaxes="1 0 0 0 1 0" fovy="{_f(OVERHEAD_FOVY)}"/>
  </worldbody>
</mujoco>
"""
