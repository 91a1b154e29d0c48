"""One colour per person of a scene (up to :data:`core.limits.MAX_PERSONS`): the top view's truth
path and marker and the scene editor's person list use the same colour for the same person."""

from __future__ import annotations

from core.limits import MAX_PERSONS

#: well apart in hue and lightness on the dark top view and the light panel (RGB)
PERSON_COLOURS: tuple[tuple[int, int, int], ...] = (
    (255, 255, 255),  # person 0: white, as before (the paper's single person)
    (255, 127, 14),
    (44, 160, 255),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (188, 189, 34),
)
assert len(PERSON_COLOURS) >= MAX_PERSONS


def person_colour(index: int) -> tuple[int, int, int]:
    """The colour of person ``index`` (0-based)."""
    return PERSON_COLOURS[index % len(PERSON_COLOURS)]
