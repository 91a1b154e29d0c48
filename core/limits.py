"""The limits of what RadarTune reads and runs, in one table.

Every input the CLI and the app read (scene JSON, TI ``.cfg``, tracker parameter JSON, data-set
``.npz``) is checked against these before anything is allocated or run, so a file that would
exhaust memory, overflow the tracker's arithmetic or run for hours gets one line naming the field
and the limit instead. The values are generous for real use (the paper's scenes use one person,
~300 frames, no static reflectors and 3 x 4 x 32 x 256 radar cubes); raise one here if a real use
needs it, and its test in ``tests/core/test_limits.py`` follows.
"""

from __future__ import annotations

# ---- files ---------------------------------------------------------------------------------------
#: Largest input file read (JSON, .cfg, .npz), bytes.
MAX_INPUT_BYTES = 2 * 1024**3
#: Deepest JSON nesting of objects and arrays (a scene needs 5).
MAX_JSON_DEPTH = 64
#: Most elements in all arrays of one .npz together (8 bytes each: 800 MB).
MAX_NPZ_ELEMENTS = 100_000_000
#: Most members of one .npz.
MAX_NPZ_MEMBERS = 64

# ---- data sets -----------------------------------------------------------------------------------
#: Most frames in one data set (the paper's has 35 trajectories of <= 250 frames).
MAX_DATASET_FRAMES = 200_000
#: Most trajectories ``radartune dataset`` simulates (the paper's set has 35).
MAX_DATASET_TRAJECTORIES = 1_000
#: Most worker processes of one command.
MAX_JOBS = 256
#: Frame periods a data set may record, s.
FRAME_PERIOD_RANGE_S = (1e-4, 10.0)

# ---- scenes --------------------------------------------------------------------------------------
#: Most persons in one scene.
MAX_PERSONS = 8
#: Most frames one trajectory may last (at 80 ms, 13 minutes; the exact simulator needs ~3.4 ms
#: a frame for the paper's radar, so ~35 s).
MAX_FRAMES = 10_000
#: Most person-frames (persons x frames) one scene may simulate: bounds the total work.
MAX_PERSON_FRAMES = 20_000
#: Most scatterer-frames one scene may simulate: frames x (persons' scatterers — 1 a point
#: person, 5 a blob, 17 a walking body — + static reflectors + expected clutter points).
#: The exact simulator needs ~0.05-0.2 ms a scatterer-frame on top of ~3.4 ms a frame, so a scene
#: at this limit runs in well under a minute.
MAX_SCATTERER_FRAMES = 100_000
#: Body heights of the walking person model, m.
PERSON_HEIGHT_RANGE_M = (1.0, 2.2)
#: Farthest a person may be from the radar, and the largest |component| of an explicit
#: profile's initial position (m), velocity (m/s) and acceleration (m/s²): far beyond any
#: radar's range and any walk, small enough that the simulation's squares stay finite.
MAX_PERSON_DISTANCE_M = 1_000.0
#: Most static reflectors in one scene.
MAX_STATIC_REFLECTORS = 1_000
#: Most samples in one frame's radar cube (virtual channels x loops x ADC samples; the paper's
#: radar has 12 x 32 x 256 = 98 304).
MAX_CUBE_SAMPLES = 2**20
#: Most radar-cube samples one scene may simulate (frames x cube samples): the paper's radar
#: for MAX_FRAMES frames.
MAX_SIMULATED_SAMPLES = 1_000_000_000

# ---- tracker parameters --------------------------------------------------------------------------
#: Most tracks the tracker holds at once (its buffers are allocated for this many).
MAX_TRACKS = 200
#: Range of the positive variances and coefficients (q_coeff, r11, r22, r33, p0 entries): far
#: inside float64 so that products of a few of them in the filter cannot overflow or underflow.
VARIANCE_RANGE = (1e-12, 1e12)
#: Range of a parametric clutter density, m^-2.
CLUTTER_DENSITY_RANGE = (1e-12, 1e6)

# ---- command line --------------------------------------------------------------------------------
#: TCP ports a server may listen on (0: any free port).
PORT_RANGE = (0, 65535)

#: The table, for documentation and tests: name -> (value, what it bounds).
LIMITS: dict[str, tuple[object, str]] = {
    "MAX_INPUT_BYTES": (MAX_INPUT_BYTES, "bytes of one input file"),
    "MAX_JSON_DEPTH": (MAX_JSON_DEPTH, "nesting of JSON objects/arrays"),
    "MAX_NPZ_ELEMENTS": (MAX_NPZ_ELEMENTS, "elements of all arrays of one .npz"),
    "MAX_NPZ_MEMBERS": (MAX_NPZ_MEMBERS, "arrays in one .npz"),
    "MAX_DATASET_FRAMES": (MAX_DATASET_FRAMES, "frames of one data set"),
    "MAX_DATASET_TRAJECTORIES": (MAX_DATASET_TRAJECTORIES, "radartune dataset --trajectories"),
    "MAX_JOBS": (MAX_JOBS, "--jobs of radartune dataset"),
    "FRAME_PERIOD_RANGE_S": (FRAME_PERIOD_RANGE_S, "frame period of a data set, s"),
    "MAX_PERSONS": (MAX_PERSONS, "persons in one scene or data set"),
    "MAX_FRAMES": (MAX_FRAMES, "frames of one trajectory"),
    "MAX_PERSON_FRAMES": (MAX_PERSON_FRAMES, "persons x frames of one scene"),
    "MAX_SCATTERER_FRAMES": (MAX_SCATTERER_FRAMES, "frames x scatterers of one scene"),
    "PERSON_HEIGHT_RANGE_M": (PERSON_HEIGHT_RANGE_M, "persons[i].height_m (walking model), m"),
    "MAX_PERSON_DISTANCE_M": (MAX_PERSON_DISTANCE_M, "a person's distance from the radar, m"),
    "MAX_STATIC_REFLECTORS": (MAX_STATIC_REFLECTORS, "static reflectors in one scene"),
    "MAX_CUBE_SAMPLES": (MAX_CUBE_SAMPLES, "virtual channels x loops x samples of one frame"),
    "MAX_SIMULATED_SAMPLES": (MAX_SIMULATED_SAMPLES, "frames x cube samples of one scene"),
    "MAX_TRACKS": (MAX_TRACKS, "tracker max_tracks"),
    "VARIANCE_RANGE": (VARIANCE_RANGE, "q_coeff, r11, r22, r33, p0 entries"),
    "CLUTTER_DENSITY_RANGE": (CLUTTER_DENSITY_RANGE, "parametric clutter_density, m^-2"),
    "PORT_RANGE": (PORT_RANGE, "--port of dashboard"),
}
