"""The app's colours in one place: per-identity (tracks, persons) and per-label (points).

Every view that colours a track by its identity or a point by its label takes the colour from
here, so that track 3 is the same colour in the top view and the track table, and the legend
matches the points. Persons (ground truth) have their own palette, :mod:`app.person_colours`.
"""

from __future__ import annotations

import numpy as np

#: Ten colours far apart on a dark background (the Tableau 10 hues, lightened a little);
#: identities cycle through them.
IDENTITY_PALETTE: tuple[tuple[int, int, int], ...] = (
    (78, 161, 235),
    (255, 146, 52),
    (80, 200, 90),
    (120, 230, 190),  # mint, not red: red is the estimate's cross and the CFAR marks
    (180, 130, 230),
    (190, 130, 100),
    (245, 130, 200),
    (170, 170, 170),
    (210, 210, 60),
    (40, 210, 220),
)

#: Point colours by ground-truth label (``source``: person >= 0, -1 clutter, -2 false alarm),
#: and the static reflectors of the scene.
LABEL_COLOURS: dict[str, tuple[int, int, int]] = {
    "person": (255, 140, 0),
    "clutter": (60, 140, 255),
    "false alarm": (160, 160, 160),
    "static": (150, 75, 0),
}

#: What each label means, for legends and tooltips.
LABEL_MEANING: dict[str, str] = {
    "person": "detection of a person (source >= 0)",
    "clutter": "detection of a clutter reflector (source -1)",
    "false alarm": "noise or sidelobe detection matching no reflector (source -2)",
    "static": "static reflector of the scene (removed by clutter removal unless it moves)",
}


def identity_colour(identity: int) -> tuple[int, int, int]:
    """Colour of track or person ``identity`` (any int; negative ids wrap too)."""
    return IDENTITY_PALETTE[int(identity) % len(IDENTITY_PALETTE)]


def identity_index(identities: np.ndarray) -> np.ndarray:
    """Palette index of each identity, ``(n,)`` int (vectorised :func:`identity_colour`)."""
    return np.mod(np.asarray(identities, dtype=np.int64), len(IDENTITY_PALETTE))


def label_key(source: np.ndarray) -> np.ndarray:
    """Label index of each point: 0 person, 1 clutter, 2 false alarm (``LABEL_COLOURS`` order)."""
    s = np.asarray(source)
    return np.clip(-s, 0, 2).astype(np.int64)


def hex_colour(rgb: tuple[int, int, int]) -> str:
    """``#rrggbb`` for Qt style sheets and HTML legends."""
    return "#{:02x}{:02x}{:02x}".format(*rgb)
