"""A small scene for the CLI tests: one person walking a straight line, no clutter."""

from __future__ import annotations

from typing import Any


def small_scene(*, velocity_mps: tuple[float, float] = (0.0, -1.2), frames: int = 6) -> dict:
    """Scene JSON (as a dict) of one person starting at (1, 5) m with ``velocity_mps``."""
    person: dict[str, Any] = {
        "trajectory": {
            "initial_position_m": [1.0, 5.0],
            "initial_velocity_mps": list(velocity_mps),
            "acceleration_mps2": [0.0, 0.0],
            "frames": frames,
        }
    }
    return {
        "schema_version": 1,
        "radar": "paper",
        "seed": 2,
        "clutter_density_per_m2": 0.0,
        "persons": [person],
    }
