"""Object and receptacle types with AI2-THOR's semantics (the kinds of things in ALFRED's rooms).

Each :class:`TypeInfo` says what the type can do (pick up, open, toggle, slice, hold things), how big it
is (a receptacle only takes objects up to its capacity, or only the types it lists) and how it may look
(colours and shapes used by the visual-appearance subset and by the renderer).

The global action list is derived from this table: one ``find`` per type, one ``pick up`` per pickupable
type, ``open``/``close`` per openable, ``turn on``/``turn off`` per toggleable and ``slice`` per sliceable.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, get_args

__all__ = [
    "COLORS",
    "KNIVES",
    "LAMPS",
    "ROOMS",
    "TYPES",
    "TypeInfo",
    "fits",
    "info",
    "is_movable_receptacle",
]


@dataclass(frozen=True)
class TypeInfo:
    name: str
    """AI2-THOR type name, used verbatim in action names (``find a SinkBasin``)."""
    noun: str
    """Plain English noun for instructions (``sink basin``)."""
    pickupable: bool = False
    receptacle: bool = False
    openable: bool = False
    toggleable: bool = False
    sliceable: bool = False
    dirtyable: bool = False
    """Can start dirty and be cleaned under a running faucet."""
    size: int = 2
    """1 tiny, 2 small, 3 medium, 4 large (pickupables); receptacles take objects up to ``capacity``."""
    capacity: int = 0
    only: tuple[str, ...] = ()
    """If set, the receptacle takes only these types (a toaster takes bread)."""
    colors: tuple[str, ...] = ()
    """Colours an instance may have; the first is the usual one."""
    shapes: tuple[str, ...] = ()
    """Shape words an instance may have (``tall``/``short``, ``round``/``square``)."""
    uses: tuple[str, ...] = field(default=())
    """Common-sense descriptions, in our words, for the common_sense subset."""


def _t(name: str, noun: str, **kw) -> TypeInfo:
    return TypeInfo(name=name, noun=noun, **kw)


_P = dict(pickupable=True)

TYPES: dict[str, TypeInfo] = {t.name: t for t in [
    # --- pickupable objects -------------------------------------------------------------------------------
    _t("AlarmClock", "alarm clock", **_P, size=2, colors=("black", "red", "white"),
       uses=("the gadget that rings to wake you up", "the bedside device that tells the time and buzzes in the morning")),
    _t("Apple", "apple", **_P, sliceable=True, dirtyable=True, size=2, colors=("red", "green", "yellow"),
       uses=("a crunchy fruit that grows on trees", "the round fruit often packed in a school lunch")),
    _t("BaseballBat", "baseball bat", **_P, size=4, colors=("brown", "black"),
       uses=("the wooden club used to hit a ball in a ballgame",)),
    _t("BasketBall", "basketball", **_P, size=3, colors=("orange",),
       uses=("the bouncy orange ball that is thrown through a hoop",)),
    _t("Book", "book", **_P, size=2, colors=("red", "blue", "green", "yellow"), shapes=("thick", "thin"),
       uses=("something with many pages you can read", "a bound volume of printed pages")),
    _t("Bowl", "bowl", **_P, receptacle=True, dirtyable=True, size=2, capacity=2,
       colors=("white", "blue", "green"), shapes=("deep", "shallow"),
       uses=("a deep round dish for soup or cereal", "the rounded dish you eat porridge from")),
    _t("Box", "box", **_P, receptacle=True, openable=True, size=3, capacity=3, colors=("brown", "white"),
       uses=("a cardboard container for storing or shipping things",)),
    _t("Bread", "loaf of bread", **_P, sliceable=True, size=2, colors=("brown",),
       uses=("the baked loaf used to make sandwiches", "a loaf you can toast for breakfast")),
    _t("ButterKnife", "butter knife", **_P, dirtyable=True, size=1, colors=("silver",),
       uses=("a blunt knife for spreading butter",)),
    _t("CD", "CD", **_P, size=1, colors=("silver",),
       uses=("a shiny disc that stores music",)),
    _t("Candle", "candle", **_P, size=1, colors=("white", "red"),
       uses=("a wax stick with a wick that gives light when lit",)),
    _t("CellPhone", "cell phone", **_P, size=1, colors=("black", "white"),
       uses=("the pocket device for calls and messages", "the handheld phone you text with")),
    _t("Cloth", "cloth", **_P, dirtyable=True, size=2, colors=("blue", "red", "white"),
       uses=("a rag for wiping surfaces",)),
    _t("CreditCard", "credit card", **_P, size=1, colors=("blue", "gold"),
       uses=("the plastic card used to pay at a shop",)),
    _t("Cup", "cup", **_P, receptacle=True, dirtyable=True, size=2, capacity=1, colors=("white", "blue", "red"),
       uses=("a small vessel to drink water from",)),
    _t("DishSponge", "dish sponge", **_P, size=1, colors=("yellow", "green"),
       uses=("the soft scrubber used to wash dishes",)),
    _t("Egg", "egg", **_P, size=1, colors=("white", "brown"),
       uses=("something a hen lays that you can fry for breakfast",)),
    _t("Fork", "fork", **_P, dirtyable=True, size=1, colors=("silver",),
       uses=("the pronged utensil for eating", "the eating utensil with tines")),
    _t("GlassBottle", "glass bottle", **_P, size=2, colors=("green", "clear"),
       uses=("a see-through bottle made of glass",)),
    _t("HandTowel", "hand towel", **_P, size=2, colors=("white", "blue"),
       uses=("the small towel for drying your hands",)),
    _t("Kettle", "kettle", **_P, size=3, colors=("silver", "black"),
       uses=("the pot with a spout for boiling water for tea",)),
    _t("KeyChain", "key chain", **_P, size=1, colors=("silver",),
       uses=("the ring that keeps your house keys together",)),
    _t("Knife", "knife", **_P, dirtyable=True, size=1, colors=("silver",),
       uses=("a sharp blade for cutting food", "the sharp kitchen tool for chopping")),
    _t("Ladle", "ladle", **_P, dirtyable=True, size=2, colors=("silver",),
       uses=("the long-handled deep spoon for serving soup",)),
    _t("Laptop", "laptop", **_P, openable=True, size=3, colors=("silver", "black"),
       uses=("the portable computer you can fold shut", "a folding computer for work on the go")),
    _t("Lettuce", "head of lettuce", **_P, sliceable=True, dirtyable=True, size=2, colors=("green",),
       uses=("a leafy green vegetable for salads", "the leafy head used as the base of a salad")),
    _t("Mug", "mug", **_P, receptacle=True, dirtyable=True, size=2, capacity=1,
       colors=("white", "blue", "red", "black"), shapes=("tall", "short"),
       uses=("the handled cup for hot coffee", "what you drink your morning coffee from")),
    _t("Newspaper", "newspaper", **_P, size=2, colors=("white",),
       uses=("the folded paper with today's news",)),
    _t("Pan", "pan", **_P, receptacle=True, dirtyable=True, size=3, capacity=2, colors=("black", "silver"),
       uses=("the flat pan for frying eggs", "a shallow cooking vessel with a handle")),
    _t("Pen", "pen", **_P, size=1, colors=("blue", "black", "red"),
       uses=("something you write with in ink",)),
    _t("Pencil", "pencil", **_P, size=1, colors=("yellow", "green"),
       uses=("a graphite writing stick with an eraser", "what you sketch with and can erase")),
    _t("PepperShaker", "pepper shaker", **_P, size=1, colors=("black",),
       uses=("the shaker that holds ground black spice",)),
    _t("Pillow", "pillow", **_P, size=3, colors=("white", "blue", "red"),
       uses=("the soft cushion you rest your head on at night",)),
    _t("Plate", "plate", **_P, receptacle=True, dirtyable=True, size=2, capacity=2,
       colors=("white", "blue", "green"), shapes=("round", "square"),
       uses=("the flat dish you serve dinner on", "a flat dish for a meal")),
    _t("Plunger", "plunger", **_P, size=3, colors=("red", "black"),
       uses=("the rubber-cup tool for unblocking a toilet",)),
    _t("Pot", "pot", **_P, receptacle=True, dirtyable=True, size=3, capacity=2, colors=("silver", "black"),
       uses=("the deep cooking vessel for boiling soup", "a deep pan for making stew")),
    _t("Potato", "potato", **_P, sliceable=True, dirtyable=True, size=2, colors=("brown",),
       uses=("a starchy tuber you can mash or bake", "the root vegetable that becomes fries")),
    _t("RemoteControl", "remote control", **_P, size=1, colors=("black", "white"),
       uses=("the handheld clicker for changing TV channels", "the device that switches the television channel")),
    _t("SaltShaker", "salt shaker", **_P, size=1, colors=("white",),
       uses=("the shaker full of white seasoning",)),
    _t("ScrubBrush", "scrub brush", **_P, size=2, colors=("blue", "yellow"),
       uses=("the stiff brush for scouring a toilet",)),
    _t("SoapBar", "soap bar", **_P, size=1, colors=("white", "pink", "green"),
       uses=("a solid block used to wash your hands", "the bar that lathers when you wash")),
    _t("SoapBottle", "soap bottle", **_P, size=2, colors=("blue", "green", "white"),
       uses=("the pump bottle of liquid hand wash",)),
    _t("Spatula", "spatula", **_P, dirtyable=True, size=2, colors=("black", "silver"),
       uses=("the flat turner for flipping pancakes",)),
    _t("Spoon", "spoon", **_P, dirtyable=True, size=1, colors=("silver",),
       uses=("the utensil you eat soup with", "a small utensil for stirring tea")),
    _t("SprayBottle", "spray bottle", **_P, size=2, colors=("blue", "white"),
       uses=("the bottle with a trigger nozzle for misting cleaner",)),
    _t("Statue", "statue", **_P, size=2, colors=("gold", "white", "black"), shapes=("tall", "short"),
       uses=("a small sculpture kept as decoration", "a carved ornament for a shelf")),
    _t("TennisRacket", "tennis racket", **_P, size=4, colors=("red", "blue"),
       uses=("the strung paddle used in tennis",)),
    _t("TissueBox", "tissue box", **_P, size=2, colors=("white", "blue"),
       uses=("the box you pull a tissue from when you sneeze",)),
    _t("ToiletPaper", "toilet paper", **_P, size=2, colors=("white",),
       uses=("the paper roll kept beside the toilet",)),
    _t("Tomato", "tomato", **_P, sliceable=True, dirtyable=True, size=2, colors=("red",),
       uses=("a juicy red fruit used in salads and sauces", "the red salad fruit used to make ketchup")),
    _t("Towel", "towel", **_P, size=3, colors=("white", "blue", "red"),
       uses=("the large cloth for drying off after a shower",)),
    _t("Vase", "vase", **_P, size=2, colors=("blue", "green", "white"), shapes=("tall", "short"),
       uses=("a container for holding cut flowers", "the decorative jar you put flowers in")),
    _t("Watch", "watch", **_P, size=1, colors=("silver", "gold", "black"),
       uses=("the timepiece worn on the wrist",)),
    _t("WateringCan", "watering can", **_P, size=3, colors=("green", "red"),
       uses=("the can with a spout for watering plants",)),
    _t("WineBottle", "wine bottle", **_P, size=2, colors=("green", "red"),
       uses=("the bottle that holds red or white wine",)),
    # --- furniture, appliances and fixed receptacles -----------------------------------------------------
    _t("ArmChair", "armchair", receptacle=True, capacity=3, colors=("brown", "blue"),
       uses=("the padded single seat with armrests",)),
    _t("Bathtub", "bathtub", receptacle=True, capacity=3, colors=("white",),
       uses=("the tub you soak in for a bath",)),
    _t("BathtubBasin", "bathtub basin", receptacle=True, capacity=3, colors=("white",),
       uses=("the inside of the bath tub",)),
    _t("Bed", "bed", receptacle=True, capacity=4, colors=("white", "blue"),
       uses=("the furniture you sleep in", "the place you lie down at night")),
    _t("Cabinet", "cabinet", receptacle=True, openable=True, capacity=3, colors=("brown", "white"),
       uses=("a cupboard with a door for storing things",)),
    _t("CoffeeMachine", "coffee machine", receptacle=True, capacity=2, only=("Mug", "Cup"), colors=("black",),
       uses=("the appliance that brews coffee",)),
    _t("CoffeeTable", "coffee table", receptacle=True, capacity=4, colors=("brown", "white"),
       uses=("the low table in front of the sofa",)),
    _t("CounterTop", "counter", receptacle=True, capacity=4, colors=("gray",),
       uses=("the kitchen work surface", "the flat surface where you prepare food")),
    _t("Desk", "desk", receptacle=True, capacity=4, colors=("brown", "white"),
       uses=("the table you work or study at",)),
    _t("DeskLamp", "desk lamp", toggleable=True, colors=("black", "white"),
       uses=("the small lamp on a desk for reading light",)),
    _t("DiningTable", "dining table", receptacle=True, capacity=4, colors=("brown", "white"),
       uses=("the table where a family eats meals", "the table where dinner is served")),
    _t("Drawer", "drawer", receptacle=True, openable=True, capacity=2, colors=("brown", "white"),
       uses=("a sliding storage compartment",)),
    _t("Dresser", "dresser", receptacle=True, capacity=4, colors=("brown", "white"),
       uses=("the chest of drawers for clothes",)),
    _t("Faucet", "faucet", toggleable=True, colors=("silver",),
       uses=("the tap that water runs from",)),
    _t("FloorLamp", "floor lamp", toggleable=True, colors=("black", "white"),
       uses=("the tall standing lamp",)),
    _t("Fridge", "fridge", receptacle=True, openable=True, capacity=3, colors=("white", "silver"),
       uses=("the appliance that keeps food cold", "the cold cabinet where groceries stay fresh")),
    _t("GarbageCan", "garbage can", receptacle=True, capacity=2, colors=("gray", "black"),
       uses=("the bin where trash goes", "the container for rubbish")),
    _t("HandTowelHolder", "hand towel holder", receptacle=True, capacity=2, only=("HandTowel",), colors=("silver",),
       uses=("the ring on the wall that holds a small towel",)),
    _t("LaundryHamper", "laundry hamper", receptacle=True, capacity=3, colors=("white", "brown"),
       uses=("the basket for dirty clothes",)),
    _t("Microwave", "microwave", receptacle=True, openable=True, toggleable=True, capacity=2,
       colors=("black", "white"),
       uses=("the appliance that warms food in a minute", "the box-shaped oven that heats leftovers quickly")),
    _t("Ottoman", "ottoman", receptacle=True, capacity=4, colors=("brown", "blue"),
       uses=("the padded footrest",)),
    _t("Safe", "safe", receptacle=True, openable=True, capacity=2, colors=("gray",),
       uses=("the locked metal box for valuables",)),
    _t("Shelf", "shelf", receptacle=True, capacity=3, colors=("brown", "white"),
       uses=("a flat board on the wall for displaying things",)),
    _t("SideTable", "side table", receptacle=True, capacity=4, colors=("brown", "white"),
       uses=("the small table beside a bed or sofa", "a little table next to the sofa")),
    _t("Sink", "sink", receptacle=True, capacity=3, colors=("white", "silver"),
       uses=("the basin with a tap for washing up",)),
    _t("SinkBasin", "sink basin", receptacle=True, capacity=3, colors=("silver", "white"),
       uses=("the bowl of the sink where dishes are rinsed", "the basin where you rinse things under running water")),
    _t("Sofa", "sofa", receptacle=True, capacity=4, colors=("blue", "gray", "red"),
       uses=("the long padded seat in a living room", "the couch you relax on")),
    _t("StoveBurner", "stove burner", receptacle=True, capacity=3, only=("Pan", "Pot", "Kettle"), colors=("black",),
       uses=("the cooking ring on the stove",)),
    _t("TVStand", "TV stand", receptacle=True, capacity=4, colors=("black", "brown"),
       uses=("the low cabinet the television sits on",)),
    _t("Toaster", "toaster", receptacle=True, capacity=2, only=("Bread",), colors=("silver",),
       uses=("the appliance that browns slices of bread",)),
    _t("Toilet", "toilet", receptacle=True, capacity=2, colors=("white",),
       uses=("the bathroom fixture you flush",)),
    _t("ToiletPaperHanger", "toilet paper hanger", receptacle=True, capacity=2, only=("ToiletPaper",),
       colors=("silver",), uses=("the holder for the toilet roll",)),
    _t("TowelHolder", "towel holder", receptacle=True, capacity=3, only=("Towel",), colors=("silver",),
       uses=("the rail for hanging a bath towel",)),
]}

#: Types whose action is "turn on" and that light the room for examining.
LAMPS = ("DeskLamp", "FloorLamp")
#: Types that can slice.
KNIVES = ("Knife", "ButterKnife")
#: Room kinds (ALFRED's four).
Room = Literal["kitchen", "living_room", "bedroom", "bathroom"]
ROOMS: tuple[Room, ...] = get_args(Room)

#: Colour names -> RGB in [0, 1] (renderer and text).
COLORS: dict[str, tuple[float, float, float]] = {
    "red": (0.80, 0.12, 0.10), "green": (0.25, 0.65, 0.20), "yellow": (0.95, 0.85, 0.20),
    "blue": (0.15, 0.35, 0.80), "white": (0.93, 0.93, 0.90), "black": (0.08, 0.08, 0.09),
    "brown": (0.50, 0.32, 0.17), "orange": (0.95, 0.50, 0.10), "silver": (0.75, 0.76, 0.78),
    "gold": (0.85, 0.68, 0.20), "gray": (0.50, 0.50, 0.52), "pink": (0.95, 0.60, 0.70),
    "clear": (0.70, 0.85, 0.85),
}


def info(type_name: str) -> TypeInfo:
    return TYPES[type_name]


def is_movable_receptacle(type_name: str) -> bool:
    t = TYPES[type_name]
    return t.pickupable and t.receptacle


def fits(obj_type: str, recep_type: str) -> bool:
    """Whether an object of ``obj_type`` may be put in/on a receptacle of ``recep_type``."""
    o, r = TYPES[obj_type], TYPES[recep_type]
    if not r.receptacle:
        return False
    if r.only:
        return obj_type in r.only
    if is_movable_receptacle(recep_type) and o.receptacle:
        return False  # no dish inside a dish: keeps stacks two deep at most
    return o.size <= r.capacity
