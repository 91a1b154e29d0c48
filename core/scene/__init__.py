"""Scenes: trajectories (classes a–e, waypoints, profiles), persons, clutter, Scene and its JSON."""

from core.scene.aoi import AOI
from core.scene.clutter import ClutterDraw, draw_clutter, expected_clutter_count
from core.scene.scene import (
    Person,
    Scene,
    StaticReflector,
    class_scene,
    paper_scenes,
    person_seed,
)
from core.scene.trajectory import (
    CLASS_PARAMETERS,
    TRAJECTORY_CLASSES,
    Trajectory,
    generate_trajectory,
    integrate_eq6,
    profile_trajectory,
    waypoint_trajectory,
)

__all__ = [
    "AOI",
    "CLASS_PARAMETERS",
    "TRAJECTORY_CLASSES",
    "ClutterDraw",
    "Person",
    "Scene",
    "StaticReflector",
    "Trajectory",
    "class_scene",
    "draw_clutter",
    "expected_clutter_count",
    "generate_trajectory",
    "integrate_eq6",
    "paper_scenes",
    "person_seed",
    "profile_trajectory",
    "waypoint_trajectory",
]
