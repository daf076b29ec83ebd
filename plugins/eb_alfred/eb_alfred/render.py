"""First-person rendering of the symbolic world with the scene kit (MuJoCo). Imported only when ``render: true``.

At ``load`` the furniture is laid out along the four walls in slot order (clockwise as seen from the middle of
the room, so "left of" in the instructions is left on screen) and every instance gets its own body. After each
action :meth:`AlfredRenderer.render` mirrors the symbolic state without recompiling: movable objects are posed
on/in their receptacles (or in front of the camera when held), doors and drawers are opened or closed,
appliances switched on or off, sliced food swapped for its slices, dirty things tinted; then the agent camera is
put in front of the place it stands at, looking at what it found. When nothing the draw reads has changed since
the last frame (a failed action, finding what is already in view), that frame is served again instead of being
drawn: the same pixels and boxes without the colour and segmentation passes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from eb_alfred.catalog import COLORS, TYPES
from eb_alfred.world import World

from eb_scenekit import SceneBuilder, Surface, get_type, set_agent_pose, set_open, set_powered
from eb_scenekit.gl import import_mujoco
from eb_scenekit.pool import default_pooled, pool_stats
from eb_scenekit.render import SceneRenderer, free_camera
from eb_scenekit.scene import Wall
from eb_scenekit.visibility import colours_in_view

mujoco = import_mujoco()

__all__ = ["AlfredRenderer", "Frame", "KIT", "shared_gl_stats"]

#: ALFRED type -> (scene-kit catalogue type, scale). Sink basins, faucets and bathtub basins are parts of their
#: sink/bathtub (see ``_PARTS_OF``).
KIT: dict[str, tuple[str, float]] = {
    "AlarmClock": ("AlarmClock", 1.0), "Apple": ("Apple", 1.0), "ArmChair": ("ArmChair", 1.0),
    "BaseballBat": ("BaseballBat", 1.0), "BasketBall": ("BasketBall", 1.0), "Bathtub": ("Bathtub", 1.0),
    "Bed": ("Bed", 1.0), "Book": ("Book", 1.0), "Bowl": ("Bowl", 1.0), "Box": ("Box", 1.0),
    "Bread": ("Bread", 1.0), "ButterKnife": ("Knife", 0.8), "CD": ("CD", 1.0), "Cabinet": ("Cabinet", 1.0),
    "Candle": ("Candle", 0.8), "CellPhone": ("CellPhone", 1.0), "Cloth": ("Towel", 0.7),
    "CoffeeMachine": ("CoffeeMachine", 1.0), "CoffeeTable": ("CoffeeTable", 1.0), "CounterTop": ("CounterTop", 1.0),
    "CreditCard": ("CreditCard", 1.0), "Cup": ("Cup", 1.0), "Desk": ("Desk", 1.0),
    "DeskLamp": ("DeskLamp", 1.0), "DiningTable": ("DiningTable", 1.0), "DishSponge": ("Sponge", 1.0),
    "Drawer": ("Drawer", 1.0), "Dresser": ("Dresser", 1.0), "Egg": ("Egg", 1.0),
    "FloorLamp": ("FloorLamp", 1.0), "Fork": ("Fork", 1.0), "Fridge": ("Fridge", 1.0),
    "GarbageCan": ("GarbageCan", 1.0), "GlassBottle": ("WineBottle", 0.85), "HandTowel": ("Towel", 0.8),
    "HandTowelHolder": ("HandTowelHolder", 1.0), "Kettle": ("Kettle", 1.0), "KeyChain": ("KeyChain", 1.0),
    "Knife": ("Knife", 1.0), "Ladle": ("Ladle", 1.0), "Laptop": ("Laptop", 1.0),
    "LaundryHamper": ("LaundryHamper", 1.0), "Lettuce": ("Lettuce", 1.0), "Microwave": ("Microwave", 1.0),
    "Mug": ("Mug", 1.0), "Newspaper": ("Newspaper", 1.0), "Ottoman": ("Ottoman", 1.0),
    "Pan": ("Pan", 1.0), "Pen": ("Pen", 1.0), "Pencil": ("Pen", 1.2), "PepperShaker": ("PepperShaker", 1.0),
    "Pillow": ("Pillow", 1.0), "Plate": ("Plate", 1.0), "Plunger": ("Plunger", 1.0), "Pot": ("Pot", 1.0),
    "Potato": ("Potato", 1.0), "RemoteControl": ("RemoteControl", 1.0), "Safe": ("Safe", 1.0),
    "SaltShaker": ("SaltShaker", 1.0), "ScrubBrush": ("ScrubBrush", 1.0), "Shelf": ("Shelf", 1.0),
    "SideTable": ("SideTable", 1.0), "Sink": ("Sink", 1.0), "SoapBar": ("SoapBar", 1.0),
    "SoapBottle": ("SoapBottle", 1.0), "Sofa": ("Sofa", 1.0), "Spatula": ("Spatula", 1.0),
    "Spoon": ("Spoon", 1.0), "SprayBottle": ("SprayBottle", 1.0), "Statue": ("Statue", 1.0),
    "StoveBurner": ("StoveBurner", 1.0), "TVStand": ("TVStand", 1.0), "TennisRacket": ("TennisRacket", 1.0),
    "TissueBox": ("TissueBox", 1.0), "Toaster": ("Toaster", 1.0), "Toilet": ("Toilet", 1.0),
    "ToiletPaper": ("ToiletPaper", 1.0), "ToiletPaperHanger": ("ToiletPaperHanger", 1.0),
    "Tomato": ("Tomato", 1.0), "Towel": ("Towel", 1.0), "TowelHolder": ("TowelHolder", 1.0),
    "Vase": ("Vase", 0.8), "Watch": ("Watch", 1.0), "WateringCan": ("WateringCan", 1.0),
    "WineBottle": ("WineBottle", 1.0),
}

_PARTS_OF = {"SinkBasin": "Sink", "Faucet": "Sink", "BathtubBasin": "Bathtub"}
"""Types drawn as a part of their parent (the sink's basin and tap, the bathtub's basin)."""
_FOOD_SLICEABLE = {"Apple", "Bread", "Lettuce", "Tomato", "Potato"}
_HIDDEN = (0.0, 0.0, -5.0)
_DIRT_DARKEN = 0.72
"""Dirty things are drawn darker with the same hue (a brown tint would hide a named colour: white -> tan)."""
_EYE = 1.45
_WARM = np.array([1.0, 0.78, 0.35, 1.0])
_GLOW_PARTS = {"Microwave": ("window",), "DeskLamp": ("shade",), "FloorLamp": ("shade",)}
_CORNER = 0.75


def shared_gl_stats() -> dict[str, int]:
    """Counters of the per-process GL pool (:func:`eb_scenekit.pool.pool_stats`): ALFRED's envs of one process
    share one GL context, framebuffer set and scene buffer (images byte-identical to private renderers)."""
    return pool_stats()


@dataclass
class Frame:
    images: dict[str, np.ndarray]
    objects: list[dict[str, Any]] = field(default_factory=list)


@dataclass
class _Pose:
    pos: tuple[float, float, float]
    yaw: float
    normal: tuple[float, float] = (0.0, -1.0)
    """Inward wall normal (the way the furniture's front faces)."""


def dirty_rgba(rgba: np.ndarray) -> np.ndarray:
    """The colour of a dirty geom: the clean colour darkened, hue and alpha kept."""
    out = np.array(rgba, dtype=float).copy()
    out[:3] = out[:3] * _DIRT_DARKEN
    return out


def _rgb(color: str | None, fallback: str) -> tuple[float, float, float]:
    return COLORS.get(color or "", COLORS.get(fallback, COLORS["gray"]))


class AlfredRenderer:
    """Builds one MuJoCo scene per task and renders the agent's view of a :class:`World`."""

    def __init__(self, resolution: int = 500, multi_view: bool = False, shared_gl: bool | None = None) -> None:
        self.resolution = int(resolution)
        self.multi_view = multi_view
        self.shared_gl = default_pooled() if shared_gl is None else bool(shared_gl)
        """Borrow GL context, framebuffers and scene buffer from the process pool (same images, far less memory)."""
        self._renderer: SceneRenderer | None = None
        self.model: Any = None
        self.data: Any = None
        self.reuse_frames = True
        """Serve a frame whose scene inputs are unchanged from the previous one without drawing (see :meth:`render`)."""
        self.frames_drawn = 0
        self.frames_reused = 0
        self._last_frame: tuple[Any, dict[str, Any], Frame] | None = None

    # ------------------------------------------------------------------ building
    def load(self, world: World) -> None:
        """Lay the room out and compile it (once per task)."""
        self.close()
        furniture = sorted((o.slot, n) for n, o in world.objects.items() if o.parent is None)
        names = [n for _, n in furniture]
        widths = {n: 2 * self._half(world.objects[n].type)[1] + 0.12 for n in names}
        total = sum(widths.values()) + 1.3  # + the door
        # a room whose usable wall length (minus corners) holds every piece, about 5:4
        sy = max(3.6, (total / 2 + 4 * _CORNER) / 2.25)
        sx = 1.25 * sy
        while True:
            walls = self._fill(names, widths, sx, sy)
            if walls is not None:
                break
            sx, sy = sx * 1.06, sy * 1.06
        # keep the middle clear: deep furniture (beds) needs room
        self.size = (round(sx, 2), round(sy, 2))
        b = SceneBuilder(name="alfred", offscreen=(max(self.resolution, 500), max(self.resolution, 500)))
        shell = b.add_room(world.room, self.size, seed=len(names), door=("west", round(sy / 2 - 0.75, 2)),
                   windows=[("south", 0.0)] if world.room in ("living_room", "bedroom") else [],
                   rug=(0.9, 0.7) if world.room in ("living_room", "bedroom") else None)
        self.poses: dict[str, _Pose] = {}
        for wall, row in walls.items():
            centre, along, normal = shell.wall_frame(wall)
            used = sum(widths[n] for n in row)
            t = -used / 2
            # rows run left to right as seen from the middle of the room: along +x on the north wall and +y on
            # the west wall, the other way round on the east and south walls
            for n in (row if wall in ("north", "west") else list(reversed(row))):
                t += widths[n] / 2
                hx = self._half(world.objects[n].type)[0]
                p = centre + along * t + normal * (hx + 0.02)
                yaw = math.degrees(math.atan2(normal[1], normal[0]))
                self.poses[n] = _Pose((float(p[0]), float(p[1]), 0.0), yaw, (float(normal[0]), float(normal[1])))
                t += widths[n] / 2
        self.kit_name: dict[str, str] = {}
        for n in names:
            o = world.objects[n]
            kt, sc = KIT[o.type]
            pose = self.poses[n]
            b.add_object(kt, n, pos=pose.pos, yaw=pose.yaw, color=_rgb(o.color, "gray"), scale=sc)
            self.kit_name[n] = n
        # fixtures standing on furniture (microwave, toaster, coffee machine, desk lamp), and sink parts
        for n, o in world.objects.items():
            if o.parent is None:
                continue
            if o.type in _PARTS_OF:
                self.kit_name[n] = o.parent
                continue
            if not TYPES[o.type].pickupable:
                kt, sc = KIT[o.type]
                offset = self._fixture_offset(world, n)
                b.add_object(kt, n, pos=offset, color=_rgb(o.color, "gray"), scale=sc, parent=o.parent,
                             surface="top")
                self.kit_name[n] = n
        # movable objects: placed by pose every frame; sliceable food also gets its slices (hidden)
        for n, o in world.objects.items():
            if not TYPES[o.type].pickupable:
                continue
            kt, sc = KIT[o.type]
            shape = o.shape if o.shape in get_type(kt).shapes else None
            b.add_object(kt, n, pos=_HIDDEN, color=_rgb(o.color, TYPES[o.type].colors[0]), scale=sc, movable=True,
                         shape=shape)
            self.kit_name[n] = n
            if o.type in _FOOD_SLICEABLE:
                b.add_object("Slices", f"{n}__slices", pos=_HIDDEN, color=_rgb(o.color, "red"), movable=True)
        b.add_agent_camera("agent", pos=(0.0, 0.0), height=_EYE, fovy=60.0, marker=False)
        self.builder = b
        self._last_frame = None
        self.model, self.data = b.build()
        # nothing is simulated (the symbolic world decides), so skip collision detection: mj_forward, called on
        # every pose, door or camera change, stays cheap even with dozens of objects in one cupboard
        self.model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
        mujoco.mj_forward(self.model, self.data)
        self._renderer = SceneRenderer(self.model, self.data, self.resolution, self.resolution,
                                       pooled=self.shared_gl)
        # this renderer reuses frames itself (render() below, also for the boxes): the scene kit's own reuse
        # would only keep second copies and compare again
        self._renderer.reuse_frames = False
        self._geoms: dict[str, list[int]] = {}
        for g in range(self.model.ngeom):
            gname = mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_GEOM, g) or ""
            self._geoms.setdefault(gname.split("/", 1)[0], []).append(g)
        self._orig_rgba = self.model.geom_rgba.copy()
        self._orig_mat: dict[int, int] = {}
        self._applied: dict[tuple[str, str], Any] = {}
        self._free_adr: dict[str, int] = {}
        for n in list(world.objects) + [f"{n}__slices" for n in world.objects]:
            j = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, f"{n}/free")
            if j >= 0:
                self._free_adr[n] = int(self.model.jnt_qposadr[j])

    def _kit_obj(self, name: str) -> Any:
        """The scene kit's record of a static instance, or None for movable/absent ones."""
        try:
            return self.builder.object(name)
        except KeyError:
            return None

    @staticmethod
    def _half(alfred_type: str) -> tuple[float, float]:
        kt, sc = KIT[alfred_type]
        t = get_type(kt)
        return t.half_extents[0] * sc, t.half_extents[1] * sc

    def _fill(self, names: list[str], widths: dict[str, float], sx: float,
              sy: float) -> dict[Wall, list[str]] | None:
        """Walls in clockwise order from the middle: north (left to right), east, south, west (door at its end)."""
        order: list[Wall] = ["north", "east", "south", "west"]
        room = {"north": sx, "south": sx, "east": sy, "west": sy}
        walls: dict[Wall, list[str]] = {w: [] for w in order}
        i = 0
        for w in order:
            free = room[w] - 2 * _CORNER - (1.3 if w == "west" else 0.0)
            while i < len(names) and widths[names[i]] <= free:
                walls[w].append(names[i])
                free -= widths[names[i]]
                i += 1
        return walls if i == len(names) else None

    def _fixture_offset(self, world: World, name: str) -> tuple[float, float]:
        """Spread fixtures standing on one piece of furniture along its width."""
        parent = world.objects[name].parent
        siblings = [c for c in world.children(parent) if not TYPES[world.objects[c].type].pickupable
                    and world.objects[c].type not in _PARTS_OF]
        k, n = siblings.index(name), len(siblings)
        half_d, half_w = self._half(world.objects[parent].type)
        y = (k - (n - 1) / 2) * (2 * half_w / max(n, 1)) * 0.9
        return (-0.3 * half_d, y)  # towards the wall, leaving the front strip for small things

    # ------------------------------------------------------------------ posing
    def _surface_frame(self, world: World, recep: str, poses: dict[str, tuple]) -> tuple[np.ndarray, float, Any, float]:
        """World origin of a receptacle's support surface, its yaw, the Surface and the scale."""
        kit = self.kit_name[recep]
        o = world.objects[recep]
        if o.type in ("SinkBasin", "BathtubBasin"):
            kit_obj = self.builder.object(kit)
            surf = get_type(kit_obj.type).surface("basin")
        else:
            kit_obj = self._kit_obj(kit)
            t = get_type(KIT[o.type][0])
            surf = self._choose_surface(o.type, t)
        if recep in poses:
            pos, yaw = poses[recep]
            scale = KIT[o.type][1]
        else:
            assert kit_obj is not None
            pos, yaw, scale = kit_obj.position, kit_obj.yaw, kit_obj.scale
        c, s = math.cos(math.radians(yaw)), math.sin(math.radians(yaw))
        lx, ly = surf.center[0] * scale, surf.center[1] * scale
        if o.type == "Drawer" and o.is_open:
            lx += 0.3 * scale
        origin = np.array([pos[0] + c * lx - s * ly, pos[1] + s * lx + c * ly, pos[2] + surf.z * scale])
        return origin, yaw, surf, scale

    @staticmethod
    def _choose_surface(alfred_type: str, kit_t: Any) -> Any:
        if not kit_t.surfaces:  # a kit shape without a support surface: use its top
            hx, hy = kit_t.half_extents
            return Surface("top", kit_t.height, (hx * 0.5, hy * 0.5))
        names = [s.name for s in kit_t.surfaces]
        for pref in ("interior", "shelf_1", "board_1", "basin", "seat", "top", "bar", "ring", "arm"):
            if pref in names and not (alfred_type in ("Cabinet",) and pref == "top"):
                return kit_t.surface(pref)
        return kit_t.surfaces[0]

    def _object_poses(self, world: World) -> dict[str, tuple[tuple[float, float, float], float]]:
        """World (pos, yaw) of every movable instance that is not in hand, parents before children."""
        poses: dict[str, tuple[tuple[float, float, float], float]] = {}

        def place_children(recep: str) -> None:
            kids = [c for c in world.children(recep) if TYPES[world.objects[c].type].pickupable]
            if not kids:
                return
            origin, yaw, surf, scale = self._surface_frame(world, recep, poses)
            hx, hy = surf.half_extents[0] * scale, surf.half_extents[1] * scale
            if any(not TYPES[world.objects[c].type].pickupable and world.objects[c].type not in _PARTS_OF
                   for c in world.children(recep)):
                # appliances stand at the back of this counter/desk: use the front strip
                front = 0.62 * hx
                origin = origin + np.array([math.cos(math.radians(yaw)) * front, math.sin(math.radians(yaw)) * front, 0])
                hx = 0.3 * hx
            n = len(kids)
            cols = max(1, math.ceil(math.sqrt(n * max(hy, 0.01) / max(hx, 0.01))))
            rows = math.ceil(n / cols)
            c, s = math.cos(math.radians(yaw)), math.sin(math.radians(yaw))
            for k, kid in enumerate(kids):
                r, q = divmod(k, cols)
                ly = (q - (cols - 1) / 2) * (2 * hy / cols) * 0.9 if cols > 1 else 0.0
                lx = (((rows - 1) / 2 - r) * (2 * hx / rows) * 0.8) if rows > 1 else 0.0
                if world.closed_container(kid) is not None:
                    continue  # closed receptacles hide what is inside (tall things would poke through)
                p = (float(origin[0] + c * lx - s * ly), float(origin[1] + s * lx + c * ly), float(origin[2]) + 0.002)
                poses[kid] = (p, yaw + (20.0 if TYPES[world.objects[kid].type].size == 1 else 0.0))
                place_children(kid)

        for n, o in world.objects.items():
            if o.parent is None and not TYPES[o.type].pickupable:
                place_children(n)
                for c in world.children(n):
                    if world.objects[c].type in _PARTS_OF or not TYPES[world.objects[c].type].pickupable:
                        place_children(c)
        # things on the floor: in front of the furniture they were dropped at
        floor = [n for n, o in world.objects.items() if o.parent is None and o.floor_at is not None
                 and not world.is_held(n)]
        for k, n in enumerate(floor):
            base = self.poses.get(world.objects[n].floor_at or "", _Pose((0.0, 0.0, 0.0), 0.0, (1.0, 0.0)))
            hx = self._half(world.objects[world.objects[n].floor_at].type)[0] if world.objects[n].floor_at in self.poses else 0
            nx, ny = base.normal
            p = (base.pos[0] + nx * (2 * hx + 0.25) - ny * 0.15 * k, base.pos[1] + ny * (2 * hx + 0.25) + nx * 0.15 * k, 0.0)
            poses[n] = (p, base.yaw)
            place_children(n)
        return poses

    def _camera(self, world: World) -> tuple[np.ndarray, np.ndarray]:
        """Eye position and look-at point."""
        if world.place is None or world.place not in self.poses:
            sx, sy = self.size
            return np.array([0.0, -sy * 0.3, 1.6]), np.array([0.0, sy / 2, 0.9])
        pose = self.poses[world.place]
        hx, hy = self._half(world.objects[world.place].type)
        height = get_type(KIT[world.objects[world.place].type][0]).height
        n = np.array(pose.normal)
        front = np.array(pose.pos[:2]) + n * hx
        dist = max(0.95, 0.9 * hy + 0.5, 0.7 * height)
        eye = np.array([*(front + n * dist), _EYE if height > 0.5 else 1.3])
        target = self._look_at_point(world, front, height)
        return eye, target

    def _look_at_point(self, world: World, front: np.ndarray, height: float) -> np.ndarray:
        """What the camera looks at: the found object, or its closed container, or the place itself."""
        focus = world.facing
        if focus is not None and not world.is_held(focus):
            hidden_in = world.closed_container(focus)
            target = hidden_in or focus
            pose = self._last_poses.get(target)
            if pose is not None:
                return np.array([pose[0][0], pose[0][1], pose[0][2] + 0.05])
            if world.objects[target].type in ("SinkBasin", "BathtubBasin", "Faucet"):
                so = self.builder.object(self.kit_name[target])
                z = get_type(so.type).surfaces[0].z * so.scale if get_type(so.type).surfaces else 0.9
                return np.array([so.position[0], so.position[1], so.position[2] + z])
            kit = self._kit_obj(target) if target != world.place and target not in self.poses else None
            if kit is not None:
                return np.array([kit.position[0], kit.position[1], kit.position[2] + kit.height * 0.5])
        pose0 = self.poses[world.place]
        return np.array([pose0.pos[0], pose0.pos[1], min(height * 0.65, 1.1)])

    # ------------------------------------------------------------------ frame
    def render(self, world: World) -> Frame:
        assert self._renderer is not None, "call load() first"
        m, d = self.model, self.data
        poses = self._object_poses(world)
        self._last_poses = poses
        eye, target = self._camera(world)
        fwd = target - eye
        yaw = math.degrees(math.atan2(fwd[1], fwd[0]))
        pitch = math.degrees(math.atan2(fwd[2], math.hypot(fwd[0], fwd[1])))
        # held object: low in the right of the view, whatever the camera's pitch
        if world.held is not None:
            cy, sy_, cp, sp = (math.cos(math.radians(yaw)), math.sin(math.radians(yaw)),
                               math.cos(math.radians(pitch)), math.sin(math.radians(pitch)))
            f = np.array([cp * cy, cp * sy_, sp])
            right = np.array([sy_, -cy, 0.0])
            up = np.cross(right, f)
            size = max(self._half(world.objects[world.held].type))
            hp = eye + f * (0.42 + 1.2 * size) + right * 0.13 - up * (0.13 + 0.3 * size)
            poses[world.held] = ((float(hp[0]), float(hp[1]), float(hp[2])), yaw + 60.0)
            for c in world.descendants(world.held):
                poses[c] = ((float(hp[0]), float(hp[1]), float(hp[2]) + 0.03), yaw)
        for n, adr in self._free_adr.items():
            if n.endswith("__slices"):
                base = n[: -len("__slices")]
                show = world.objects[base].is_sliced and base in poses
                p, yw = poses[base] if show else (_HIDDEN, 0.0)
            else:
                sliced = world.objects[n].is_sliced and world.objects[n].type in _FOOD_SLICEABLE
                p, yw = poses[n] if (n in poses and not sliced) else (_HIDDEN, 0.0)
            d.qpos[adr:adr + 3] = p
            h = math.radians(yw) / 2
            d.qpos[adr + 3:adr + 7] = (math.cos(h), 0.0, 0.0, math.sin(h))
        for n, o in world.objects.items():
            t = TYPES[o.type]
            kit = self.kit_name.get(n)
            if kit is None:
                continue
            if t.openable and self._changed((n, "open"), o.is_open):
                try:
                    set_open(m, d, kit, 1.0 if o.is_open else 0.0)
                except KeyError:
                    pass
            if t.toggleable and self._changed((n, "on"), o.is_on):
                try:
                    set_powered(m, kit, o.is_on)
                except KeyError:
                    pass
                self._glow(kit, _GLOW_PARTS.get(o.type, ()), o.is_on)
            if t.dirtyable and self._changed((n, "dirty"), o.is_dirty):
                for g in self._geoms.get(n, []):
                    orig = self._orig_rgba[g]
                    m.geom_rgba[g] = dirty_rgba(orig) if o.is_dirty else orig
                    m.geom_rgba[g][3] = orig[3]
        set_agent_pose(m, d, "agent", (float(eye[0]), float(eye[1]), float(eye[2])), yaw=yaw, pitch=pitch)
        inputs = self._scene_inputs()
        last = self._last_frame
        if (self.reuse_frames and last is not None and last[1] == poses
                and all(np.array_equal(a, b) for a, b in zip(last[0], inputs))):
            # Nothing the renderer reads has changed since the last frame (a failed action, a "find" of what is
            # already in view): the same pixels and boxes, without the two passes (colour + segmentation, ~55 ms
            # of CPU at 500 px on llvmpipe). Copies, so a caller that edits its frame cannot change the next one.
            self.frames_reused += 1
            prev = last[2]
            return Frame(images={k: v.copy() for k, v in prev.images.items()},
                         objects=[dict(o) for o in prev.objects])
        images = {"first_person": self._renderer.rgb("agent")}
        if self.multi_view:
            sx, sy = self.size
            cam = free_camera((0.0, 0.0, 0.5), max(sx, sy) * 1.25, 90.0, -75.0)
            images["overhead"] = self._renderer.rgb(cam)
        frame = Frame(images=images, objects=self._objects(world, poses, images["first_person"]))
        self.frames_drawn += 1
        self._last_frame = (tuple(a.copy() for a in inputs), dict(poses),
                            Frame(images={k: v.copy() for k, v in images.items()},
                                  objects=[dict(o) for o in frame.objects]))
        return frame

    def _scene_inputs(self) -> tuple[np.ndarray, ...]:
        """Everything of the model and data that a draw of this scene reads and that can change after ``load``:
        joint and camera poses (the derived frames follow from them), colours, materials and lights."""
        m, d = self.model, self.data
        return (d.qpos, d.mocap_pos, d.mocap_quat, m.geom_rgba, m.geom_matid, m.geom_size, m.geom_pos,
                m.geom_quat, m.mat_rgba, m.mat_emission, m.light_active, m.light_diffuse, m.cam_fovy)

    def _objects(self, world: World, poses: dict[str, tuple], rgb: np.ndarray | None = None) -> list[dict[str, Any]]:
        # boxes from a half-size segmentation pass (4x fewer pixels than the image; boxes are scaled back)
        assert self._renderer is not None
        small = max(64, self.resolution // 2)
        k = self.resolution / small
        seg = self._renderer.segmentation("agent", small, small)
        boxes = {name: (int(b[0] * k), int(b[1] * k), min(int((b[2] + 1) * k) - 1, self.resolution - 1),
                        min(int((b[3] + 1) * k) - 1, self.resolution - 1))
                 for name, b in self._renderer.boxes_from_segmentation(seg, min_pixels=5).items()}
        # pixels and colour families each object shows (eb_scenekit.visibility), for error analysis
        index = {n: i for i, n in enumerate(self._renderer.instance_names)}
        counts = np.bincount(seg.ravel(), minlength=len(index))
        colours = colours_in_view(rgb, seg, [index[n] for n in boxes]) if rgb is not None else {}
        out = []
        for name, box in boxes.items():
            base = name[: -len("__slices")] if name.endswith("__slices") else name
            if base not in world.objects:
                continue
            pos = poses.get(base)
            out.append({"name": base, "type": world.objects[base].type, "box": tuple(int(v) for v in box),
                        "position": tuple(round(v, 3) for v in pos[0]) if pos else None,
                        "pixels": int(counts[index[name]]), "colours": colours.get(index[name], [])})
        return out

    def visible_fraction(self, world: World, resolution: int = 250) -> dict[str, float]:
        """Share of the agent's view (0..1) each instance covers in the current view (call after :meth:`render`).

        Slices count for their food; sink basins and taps count for their sink (they are one kit object).
        """
        assert self._renderer is not None, "call load() first"
        counts = self._renderer.visible_pixels("agent", resolution, resolution)
        out: dict[str, float] = {}
        for name, k in counts.items():
            base = name[: -len("__slices")] if name.endswith("__slices") else name
            if base in world.objects:
                out[base] = out.get(base, 0.0) + k / (resolution * resolution)
        return out

    def unoccluded_fraction(self, name: str, resolution: int = 250) -> float:
        """Share of the agent's view (0..1) ``name`` would cover in the current view with nothing in front of it
        (call after :meth:`render`): every other geom is made transparent for one segmentation pass. Against
        :meth:`visible_fraction` it says how much of the object is hidden (a bowl behind a box shows its rim)."""
        assert self._renderer is not None and self.model is not None, "call load() first"
        mine = set(self._geoms.get(self.kit_name.get(name, name), [])) | set(self._geoms.get(f"{name}__slices", []))
        saved = self.model.geom_rgba.copy()
        hide = np.ones(self.model.ngeom, dtype=bool)
        hide[sorted(mine)] = False
        self.model.geom_rgba[hide, 3] = 0.0  # MuJoCo draws no geom whose alpha is 0
        try:
            counts = self._renderer.visible_pixels("agent", resolution, resolution)
        finally:
            self.model.geom_rgba[:] = saved
        return sum(k for n, k in counts.items() if n in (name, f"{name}__slices")) / (resolution * resolution)

    def looks(self, name: str) -> dict[str, Any]:
        """What the compiled model draws for one instance: its mean colour (current, e.g. dirty) and its
        axis-aligned size (dx, dy, dz) in metres, measured from the geoms."""
        assert self.model is not None, "call load() first"
        m, d = self.model, self.data
        geoms = self._geoms.get(self.kit_name.get(name, name), [])
        if not geoms:
            raise KeyError(f"{name!r} has no geoms in this scene")
        rgb = np.mean([m.geom_rgba[g][:3] for g in geoms], axis=0)
        # the biggest geom's colour is the one a viewer names (trims and labels are small)
        vols = [float(np.prod(m.geom_aabb[g][3:])) for g in geoms]
        main = m.geom_rgba[geoms[int(np.argmax(vols))]][:3]
        pts = []
        for g in geoms:
            c, h = m.geom_aabb[g][:3], m.geom_aabb[g][3:]
            R = d.geom_xmat[g].reshape(3, 3)
            for sx in (-1, 1):
                for sy in (-1, 1):
                    for sz in (-1, 1):
                        pts.append(d.geom_xpos[g] + R @ (c + h * np.array([sx, sy, sz])))
        p = np.array(pts)
        ext = p.max(axis=0) - p.min(axis=0)
        kinds = sorted(int(m.geom_type[g]) for g in geoms)
        return {"rgb": tuple(float(v) for v in main), "mean_rgb": tuple(float(v) for v in rgb),
                "size": tuple(float(v) for v in ext), "geoms": len(geoms), "geom_kinds": kinds}

    def _glow(self, kit: str, parts: tuple[str, ...], on: bool) -> None:
        """Make a running microwave's window and a lit lamp's shade glow warm (easier to see than the bulb)."""
        if not parts:
            return
        glow = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_MATERIAL, "eb_glow")
        for g in self._geoms.get(kit, []):
            gname = mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_GEOM, g) or ""
            if gname.split("/", 1)[1].split("_")[0] not in parts:
                continue
            if g not in self._orig_mat:
                self._orig_mat[g] = int(self.model.geom_matid[g])
            self.model.geom_rgba[g] = _WARM if on else self._orig_rgba[g]
            self.model.geom_matid[g] = glow if on else self._orig_mat[g]

    def _changed(self, key: tuple[str, str], value: Any) -> bool:
        if self._applied.get(key, object()) == value:
            return False
        self._applied[key] = value
        return True

    def raw_render_ms(self, repeats: int = 5) -> float:
        """Median time of one bare RGB render of the current scene (no state sync), in milliseconds."""
        import time

        assert self._renderer is not None
        times = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            self._renderer.rgb("agent")
            times.append((time.perf_counter() - t0) * 1000)
        return float(np.median(times))

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        self.model = self.data = None
        self._last_frame = None

