"""The fidelity levels: one registry, one small interface per level (docs/fidelity-models.md).

Every level simulates one frame (:class:`FrameSimulator`, the GUI's and the reference's entry
point) and may simulate all frames of a trajectory in one call (:class:`FramesSimulator`, the
data-set path), which gives the per-frame entry point's frames bit for bit with the same
per-frame generators (tested). Adding a level is one entry in :data:`LEVELS`; the pipeline and the
benchmarks take their levels from here (an unknown name: one InputError naming them, CLI exit 2).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType
from typing import Protocol

import numpy as np

from core.config import ProcessingSettings, RadarConfig
from core.errors import InputError
from core.simulation.antenna import AntennaGain
from core.simulation.fast import FramesOutput, simulate_frame_fast, simulate_frames_fast
from core.simulation.frame import FrameOutput, simulate_frame
from core.simulation.measurement import simulate_frame_measurement, simulate_frames_measurement
from core.simulation.scatterers import Scatterers


class FrameSimulator(Protocol):
    """One frame: reflectors and the frame's noise generator → point cloud (and map)."""

    def __call__(
        self,
        radar: RadarConfig,
        scatterers: Scatterers,
        rng: np.random.Generator,
        *,
        antenna: AntennaGain,
        settings: ProcessingSettings = ...,
        keep_rd_map: bool = ...,
        elevation: bool | None = ...,
        noise: bool = ...,
    ) -> FrameOutput: ...


class FramesSimulator(Protocol):
    """Many frames in one call; frame ``f`` draws only from ``rngs[f]``."""

    def __call__(
        self,
        radar: RadarConfig,
        frames: Sequence[Scatterers],
        rngs: Sequence[np.random.Generator | None],
        *,
        antenna: AntennaGain,
        settings: ProcessingSettings = ...,
        elevation: bool | None = ...,
        noise: bool = ...,
    ) -> FramesOutput: ...


@dataclass(frozen=True, slots=True, kw_only=True)
class FidelityLevel:
    """A simulator level: its name, what it models, its per-frame and batch entry points.

    ``simulate_frames`` is ``None`` for a level without a batch path (the pipeline then runs
    ``simulate_frame`` frame by frame).
    """

    name: str
    description: str
    simulate_frame: FrameSimulator
    simulate_frames: FramesSimulator | None = None


#: The fidelity levels by name, the reference first, cheapest last.
LEVELS: Mapping[str, FidelityLevel] = MappingProxyType(
    {
        level.name: level
        for level in (
            FidelityLevel(
                name="exact",
                description="every ADC sample synthesised with receiver noise, then the chain's "
                "FFTs, CFAR and angle FFTs (the reference)",
                simulate_frame=simulate_frame,
            ),
            FidelityLevel(
                name="fast",
                description="the range-Doppler spectrum in closed form with the noise drawn per "
                "cell, then the exact chain's detection",
                simulate_frame=simulate_frame_fast,
                simulate_frames=simulate_frames_fast,
            ),
            FidelityLevel(
                name="measurement",
                description="detections drawn from a statistical model of the chain (CFAR on "
                "drawn cells, Cramer-Rao errors, a measured false-alarm pool)",
                simulate_frame=simulate_frame_measurement,
                simulate_frames=simulate_frames_measurement,
            ),
        )
    }
)


def fidelity_level(name: str) -> FidelityLevel:
    """The level called ``name`` (:class:`InputError` naming the levels for an unknown one)."""
    try:
        return LEVELS[name]
    except KeyError:
        raise InputError(
            f"fidelity must be one of {sorted(LEVELS)}, got fidelity={name!r}"
        ) from None
