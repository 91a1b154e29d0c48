"""The data set a study tracks: a given ``.npz`` or the paper's data set, cached on disk.

Workers are separate processes (possibly on other machines), so they receive a file path, never
an in-memory data set, and a trial never simulates: the paper's data set is simulated once by
:func:`core.pipeline.paper_dataset_file` (cached under its content key) before workers start.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from core.errors import InputError


def resolve_dataset(
    dataset: str | None, *, n_trajectories: int = 35, person_model: str | None = None
) -> str:
    """A data-set argument → an existing ``.npz`` path.

    ``None`` or ``"paper"``: the paper's data set of seed 0 with the default person model
    (:data:`core.scene.scene.DEFAULT_PERSON_MODEL`, the walking body); ``"paper:SEED"``: of
    another seed (35 trajectories, 7 per class); ``"paper:SEED:MODEL"``: with the person model
    ``MODEL`` (``point``, ``blob`` (former name ``extended``) or ``walking``; same trajectories and
    seeds); anything else: a path to a data-set file. ``person_model``, if given, applies to
    the ``paper`` forms without a model (and must agree with one given in the string).
    """
    from core.scene.scene import DEFAULT_PERSON_MODEL

    if dataset in (None, "", "paper") or str(dataset).startswith("paper:"):
        seed = 0
        model = person_model or DEFAULT_PERSON_MODEL
        parts = str(dataset).split(":") if dataset else ["paper"]
        if len(parts) > 3:
            raise InputError(f"data set {dataset!r}: expected paper:SEED or paper:SEED:MODEL")
        if len(parts) >= 2:
            try:
                seed = int(parts[1])
            except ValueError:
                raise InputError(
                    f"data set {dataset!r}: expected paper:SEED or paper:SEED:MODEL"
                ) from None
        if len(parts) == 3:
            if person_model is not None and person_model != parts[2]:
                raise InputError(
                    f"data set {dataset!r} names person model {parts[2]!r}, "
                    f"but --person-model is {person_model!r}"
                )
            model = parts[2]
        from core.pipeline import paper_dataset_file
        from core.scene.scene import PERSON_MODELS, person_model_kind

        try:
            person_model_kind(model)
        except InputError:
            raise InputError(
                f"data set {dataset!r}: person model must be one of {list(PERSON_MODELS)}, "
                f"got {model!r}"
            ) from None
        return str(paper_dataset_file(seed, n_trajectories, person_model=model))
    if person_model is not None:
        raise InputError(
            f"--person-model {person_model!r} applies to the paper data sets only, "
            f"not to the file {dataset!r}"
        )
    path = Path(dataset)
    if not path.is_file():
        raise InputError(f"data set {dataset!r} does not exist")
    return str(path)


def person_model_of(path: str) -> str:
    """The person model a data set's (first) person was simulated with (``"point"`` when its
    scenes name none: the paper's person, and data sets that were not simulated)."""
    from core.dataset import Dataset

    scenes = Dataset.load(path).scene()
    first: Any = scenes[0] if isinstance(scenes, list) and scenes else {}
    persons = first.get("persons", [{}]) if isinstance(first, dict) else [{}]
    return str((persons[0] if persons else {}).get("model", "point"))


def like_training(spec: str | None, training_path: str) -> str | None:
    """A ``paper`` / ``paper:SEED`` spec without a person model gets the training set's, so a
    validation or generalisation set is made like the set the parameters were tuned on."""
    if spec is None or not (spec == "paper" or spec.startswith("paper:")) or spec.count(":") > 1:
        return spec
    seed = spec.split(":")[1] if ":" in spec else "0"
    return f"paper:{seed}:{person_model_of(training_path)}"


def paper_dataset_variant(
    path: str,
    *,
    seed: int | None = None,
    clutter_factor: float = 1.0,
    progress: Callable[[int, int], None] | None = None,
) -> str:
    """The paper data set made like the one at ``path``, of another seed and/or scene clutter.

    ``path`` must hold a paper data set (:func:`core.pipeline.paper_dataset`): its scenes are
    checked against :func:`core.scene.paper_scenes` of its seed, person model, trajectory count
    and persons per trajectory. The variant has the same person model, counts, radar and
    fidelity; ``seed`` (default: the set's own) and the scene clutter rate λ (Poisson clutter
    reflectors per m² of the AOI per frame, :attr:`core.scene.Scene.clutter_density_per_m2`;
    the paper's 0.02 m⁻²) multiplied by ``clutter_factor`` > 0. Only the clutter changes with
    the factor: trajectories, persons and simulation seeds stay. Simulated on first use (cached
    by content key, like every data set; ``progress(done, total)`` per trajectory); with factor
    1 it is :func:`core.pipeline.paper_dataset_file` of that seed itself.

    Returns
    -------
    str
        Path of the cached ``.npz``.
    """
    import dataclasses
    import json
    import math

    from core.dataset import Dataset
    from core.pipeline import build_dataset, dataset_key, default_cache_dir, paper_dataset_file
    from core.scene import paper_scenes

    if not (math.isfinite(clutter_factor) and clutter_factor > 0):
        raise InputError(f"clutter_factor must be a positive number, got {clutter_factor!r}")
    ds = Dataset.load(path)
    stored = ds.scene()
    items = stored if isinstance(stored, list) else [stored]
    model = person_model_of(path)
    n_persons = max(int(ds.n_persons), 1)
    try:
        scenes = paper_scenes(
            int(ds.seed), ds.n_trajectories, person_model=model, n_persons=n_persons
        )
    except InputError:
        scenes = []
    if json.loads(json.dumps([s.to_dict() for s in scenes])) != items:
        raise InputError(f"data set {path!r} is not a paper data set (its scenes are not "
                         "paper_scenes of its seed); its variants cannot be made")  # fmt: skip
    seed = int(ds.seed) if seed is None else int(seed)
    if clutter_factor == 1.0:
        return str(paper_dataset_file(seed, ds.n_trajectories, fidelity=ds.fidelity,
                                      person_model=model, n_persons=n_persons,
                                      progress=progress))  # fmt: skip
    scenes = [
        # λ' = f · λ
        dataclasses.replace(s, clutter_density_per_m2=s.clutter_density_per_m2 * clutter_factor)
        for s in paper_scenes(seed, ds.n_trajectories, person_model=model, n_persons=n_persons)
    ]
    seeds = [s.seed for s in scenes]
    root = default_cache_dir()
    key = dataset_key(scenes, fidelity=ds.fidelity, seed=seed, seeds=seeds)
    out = root / "datasets" / f"{key}.npz"
    if not out.is_file():
        build_dataset(scenes, seeds=seeds, fidelity=ds.fidelity, seed=seed, cache_dir=root,
                      progress=progress)  # fmt: skip
    return str(out)
