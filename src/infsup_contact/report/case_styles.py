"""The colour and marker of every built-in space, keyed by its id: the one table of the report
that names case ids (data, not a special case: the registry says what a space is, this table
how it is drawn). A space without a row (a user's) is drawn in :data:`NEUTRAL` with marker "8".
"""
from types import MappingProxyType

#: Okabe & Ito (2008), "Color Universal Design": distinguishable under the common
#: colour-vision deficiencies.
OKABE_ITO = MappingProxyType({
    "black": "#000000", "orange": "#E69F00", "sky_blue": "#56B4E9", "bluish_green": "#009E73",
    "yellow": "#F0E442", "blue": "#0072B2", "vermillion": "#D55E00", "reddish_purple": "#CC79A7",
})
#: colour for things that are not a case (references, Pareto front, meshes), and for a space
#: without a style of its own (a user's).
NEUTRAL = "#4d4d4d"
WIDE_MARKERS = ("o", "s", "^", "v", "<", ">", "D", "d", "p", "h", "H", "8")
"""Markers with a body: the figures tell k apart by the marker's fill style (none, full, left
half, top half), which thin markers such as ``P``, ``X``, ``+``, ``x`` and ``*`` do not show."""
#: case id → (Okabe–Ito colour name, marker); a space not listed is drawn :data:`NEUTRAL`, "8".
CASE_STYLES = MappingProxyType({
    "T3": ("blue", "o"), "R5.2": ("orange", "s"), "T4": ("bluish_green", "^"), "R5.4": ("vermillion", "D"),
    "T5": ("reddish_purple", "v"), "DUAL": ("black", "p"), "DUAL-ALL": ("sky_blue", "h"),
    "DUAL-Q9": ("black", "H"), "DUAL-Q9-ALL": ("sky_blue", "d"), "DUAL-Q8": ("vermillion", "<"),
    "TDUAL-Q8": ("orange", ">"), "TDUAL-Q9": ("bluish_green", "8"), "PWLIN-Q9": ("reddish_purple", "p"),
    "DUAL-T6": ("vermillion", "h"), "TDUAL-T6": ("bluish_green", "d"), "PWLIN-T6": ("reddish_purple", "H"),
    "Q8": ("blue", "s"), "Q8-ALL": ("sky_blue", "s"), "LIN0-Q8": ("bluish_green", "o"), "DISC-P1": ("vermillion", "v"),
    "LINDUAL0-Q8": ("reddish_purple", "^"), "LINDUAL-Q8": ("yellow", "^"), "PGLIN0-Q8": ("black", "D"),
    "PGLIN-Q8": ("sky_blue", "D"),
})
