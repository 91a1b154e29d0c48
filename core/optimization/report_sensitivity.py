"""The report's sensitivity sections: importance, one-at-a-time sweeps, clutter robustness.

:func:`sensitivity_entry` computes, per motion model, the ``sensitivity`` entry of
``report.json``; :func:`plot_importance` and :func:`plot_oat` draw it and
:func:`sensitivity_markdown` writes it into ``report.md``:

- **importance** — PED-ANOVA importances of every study of the model
  (:func:`core.optimization.sensitivity.parameter_importance`), a bar plot
  ``importance_<model>.png``;
- **one-at-a-time** — the chosen parameters (by validation when the studies were validated,
  else the best trial: :func:`core.optimization.testsets.chosen_params`) with each parameter of
  eq. (15) swept across its bounds, the others fixed, scored on the chosen study's training set
  and on the held-out set (the report's generalisation set) with the paper's ``L_t`` and the
  capped loss (:func:`core.optimization.sensitivity.oat_sweep`); small multiples
  ``sensitivity_<model>.png``;
- **clutter robustness** — the chosen parameters re-tracked with the tracker's clutter density
  ρ scaled ×0.2 … ×5, on the training and held-out sets and on their variants with the scene
  clutter rate λ ×0.5 and ×2 (:func:`core.optimization.data.paper_dataset_variant`, paper data
  sets only): :func:`core.evaluation.robustness.clutter_robustness`, a table.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from core.errors import InputError
from core.files import save_figure
from core.optimization.sensitivity import IMPORTANCE_EVALUATOR, OAT_POINTS

#: λ factors of the data-set variants besides ×1.
LAMBDA_VARIANTS = (0.5, 2.0)


def _say(progress: Callable[[str], None] | None, line: str) -> None:
    if progress is not None:
        progress(line)


def sensitivity_entry(
    storage: str,
    studies: Sequence[Any],
    *,
    heldout_path: str | None,
    training_path: str | None = None,
    oat_points: int = OAT_POINTS,
    clutter_variants: bool = True,
    progress: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """The ``sensitivity`` entry of the report (see the module docstring).

    Parameters
    ----------
    storage
        Storage URL of the studies.
    studies
        The report's study records (``name``, ``model``, ``trials``, ``best``).
    heldout_path
        Data set no study trained on (the report's generalisation set); None: training only.
    training_path
        The report's training set, swept instead of the chosen study's own training set when
        that file is absent here (a note says so).
    oat_points
        Grid points per parameter; 0: no one-at-a-time sweep.
    clutter_variants
        Simulate (or take from the cache) the λ ×0.5 and ×2 variants of paper data sets.
    progress
        Called with a line of progress.
    """
    from core.dataset import Dataset
    from core.evaluation.robustness import RHO_FACTORS, clutter_robustness
    from core.optimization.data import paper_dataset_variant
    from core.optimization.objective import make_losses
    from core.optimization.sensitivity import oat_sweep, parameter_importance
    from core.optimization.storage import load_existing_study, open_storage
    from core.optimization.testsets import chosen_params
    from core.tracking import TrackerParams

    store = open_storage(storage, create=False)
    entry: dict[str, Any] = {"evaluator": IMPORTANCE_EVALUATOR, "models": {}, "notes": []}
    heldout = Dataset.load(heldout_path) if heldout_path else None
    if heldout_path:
        trained = sorted({s.name for s in studies if _same_file(s.dataset, heldout_path)})
        if trained:
            entry["notes"].append(f"the held-out set {heldout_path!r} is the training set of "
                                  f"{', '.join(trained)}: pass another --generalisation set "
                                  "(e.g. paper:2000) for a held-out one")  # fmt: skip
    for model in ("cv", "ca"):
        mine = sorted((s for s in studies if s.model == model and s.best is not None),
                      key=lambda s: s.name)  # fmt: skip
        if not mine:
            continue
        m: dict[str, Any] = {"importance": [], "importance_skipped": []}
        for s in mine:
            try:
                m["importance"].append(
                    {"study": s.name, **parameter_importance(s.trials, model).to_dict()}
                )
            except InputError as exc:
                m["importance_skipped"].append({"study": s.name, "reason": exc.message})
        params, name, number, how = chosen_params(storage, [s.name for s in mine], model)
        study = load_existing_study(store, name)
        attrs = dict(study.user_attrs) if study is not None else {}
        value = next(t.value for s in mine if s.name == name for t in s.trials
                     if t.number == number)  # fmt: skip
        m.update({"study": name, "trial": number, "chosen_by": how, "params": params,
                  "value_in_study": value, "loss": attrs.get("loss", "paper")})  # fmt: skip
        tracker = attrs.get("objective") == "tracker"
        train_path = attrs.get("dataset") if tracker else None
        if train_path and not Path(train_path).is_file() and training_path:
            # the storage came from another machine: the report's own training set stands in
            entry["notes"].append(f"{model.upper()}: study {name!r} trained on {train_path!r}, "
                                  f"absent here; swept on {training_path!r} instead")  # fmt: skip
            train_path = training_path
        train = Dataset.load(train_path) if train_path else None
        if tracker and train is None:
            entry["notes"].append(f"{model.upper()}: study {name!r} records no training set; "
                                  "no sweeps or clutter robustness")  # fmt: skip
        elif oat_points:
            sources: dict[str, Any] = {
                "training": make_losses(str(attrs.get("objective", "tracker")), model, train,
                                        capped=True,
                                        **dict(attrs.get("objective_options") or {}))
            }  # fmt: skip
            if tracker and heldout is not None:
                sources["held-out"] = make_losses("tracker", model, heldout, capped=True)
            _say(progress, f"{model.upper()}: one-at-a-time sweeps ({oat_points} points)")
            sweeps = oat_sweep(sources, params, n_points=oat_points, progress=progress)
            m["oat"] = {label: {p: s.to_dict() for p, s in per.items()}
                        for label, per in sweeps.items()}  # fmt: skip
        if tracker and train is not None and train_path is not None:
            sets: dict[str, Any] = {"training": train}
            paths: dict[str, str] = {"training": str(train_path)}
            if heldout is not None and heldout_path is not None:
                sets["held-out"] = heldout
                paths["held-out"] = str(heldout_path)
            if clutter_variants:
                for label, p in list(paths.items()):
                    for f in LAMBDA_VARIANTS:
                        try:
                            _say(progress, f"{label} data set with λ ×{f:g} (simulated on "
                                           "first use, cached)")  # fmt: skip
                            v = paper_dataset_variant(p, clutter_factor=f)
                        except InputError as exc:
                            note = f"{label}: no λ variants ({exc.message})"
                            if note not in entry["notes"]:
                                entry["notes"].append(note)
                            break
                        sets[f"{label}, λ ×{f:g}"] = Dataset.load(v)
            _say(progress, f"{model.upper()}: clutter robustness")
            cr = clutter_robustness(TrackerParams.from_dict(params), sets, RHO_FACTORS)
            m["clutter"] = cr.to_dict()
        entry["models"][model] = m
    return entry


def _same_file(a: str, b: str) -> bool:
    try:
        return bool(a) and Path(a).resolve() == Path(b).resolve()
    except OSError:
        return False


def plot_importance(entry: dict[str, Any], model: str, path: Path) -> bool:
    """Horizontal bars of the PED-ANOVA importance per parameter, one colour per study."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from core.tracking.space import parameter, search_space

    imps = entry["models"].get(model, {}).get("importance", [])
    if not imps:
        return False
    names = [b.name for b in search_space(model)]
    # most important (by the mean over the studies) at the top
    mean = {n: float(np.mean([i["values"][n] for i in imps])) for n in names}
    names.sort(key=lambda n: mean[n])
    y = np.arange(len(names))
    h = 0.8 / len(imps)
    fig, ax = plt.subplots(figsize=(6.5, 0.33 * len(names) + 1.4))
    for j, imp in enumerate(imps):
        ax.barh(y - 0.4 + (j + 0.5) * h, [imp["values"][n] for n in names], height=h,
                label=f"{imp['study']} ({imp['n_trials']} trials, γ' = "
                      f"{imp['target_quantile']:.2f})")  # fmt: skip
    ax.set_yticks(y, [parameter(n).label for n in names], fontsize=8)
    ax.set_xlabel("importance (PED-ANOVA, sums to 1 per study)")
    ax.set_title(f"{model.upper()}: which parameters the best trials needed")
    ax.grid(True, axis="x", alpha=0.3)
    ax.legend(fontsize=7, loc="lower right")
    save_figure(fig, path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return True


def plot_oat(entry: dict[str, Any], model: str, path: Path) -> bool:
    """Small multiples: each parameter swept, the loss over its value at the optimum.

    Every curve is divided by its own value at the optimum (so L_t and the capped loss, on the
    training and the held-out set, share one log axis); the dotted line is the optimum.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    from core.tracking.space import parameter

    oat = entry["models"].get(model, {}).get("oat")
    if not oat:
        return False
    params = list(next(iter(oat.values())))
    ncol = 4
    nrow = math.ceil(len(params) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(3.2 * ncol, 2.5 * nrow), squeeze=False)
    colours = {"training": "tab:blue", "held-out": "tab:orange"}
    for ax, name in zip(axes.flat, params):
        b = parameter(name)
        for label, per in oat.items():
            s = per[name]
            x = np.array(s["values"])
            i = s["optimum_index"]
            for key, ls in (("loss", "-"), ("capped", "--")):
                yv = np.array([np.nan if v is None else v for v in s[key]], dtype=float)
                if not np.isfinite(yv[i]) or yv[i] <= 0:
                    continue
                what = "L_t" if key == "loss" else "capped"
                ax.plot(x, yv / yv[i], ls, color=colours.get(label, "tab:green"), lw=1.2,
                        marker="." if key == "loss" else None, ms=3,
                        label=f"{what}, {label}")  # fmt: skip
            ax.axvline(x[i], color="k", ls=":", lw=0.8)
        if b.log:
            ax.set_xscale("log")
        ax.set_yscale("log")
        # plain numbers on the ratio axis; minor ticks labelled only when it spans < a decade
        plain = matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}")
        lo, hi = ax.get_ylim()
        ax.yaxis.set_major_formatter(plain)
        ax.yaxis.set_minor_formatter(plain if hi < 10 * lo else matplotlib.ticker.NullFormatter())
        ax.set_title(b.label, fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, which="major", alpha=0.3)
    for ax in list(axes.flat)[len(params) :]:
        ax.axis("off")
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.supylabel("loss / loss at the optimum")
    fig.suptitle(f"{model.upper()}: one parameter at a time around the chosen parameters "
                 "(dotted: the optimum)")  # fmt: skip
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    save_figure(fig, path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return True


def _f(v: float | None, fmt: str) -> str:
    return "–" if v is None or not math.isfinite(v) else format(v, fmt)


def _scaled(v: float | None, k: float) -> float | None:
    return None if v is None else v * k


def sensitivity_markdown(r: dict[str, Any]) -> list[str]:
    """Markdown of the ``sensitivity`` entry (empty without one)."""
    from core.tracking.space import parameter

    e = r.get("sensitivity")
    if not e or not e["models"]:
        return []
    lines = [
        "",
        "## Sensitivity",
        "",
        f"### Parameter importance ({e['evaluator']})",
        "",
        "Optuna's PED-ANOVA evaluator on each study's completed trials: how much each parameter "
        "separates the best trials (the top γ' of the objective; γ' raised from 0.1 until it "
        "holds 5 trials) from all of them. Pruned trials do not enter (their value is the loss of "
        "a prefix of the trajectories). fANOVA and mean decrease impurity would need "
        "scikit-learn, which RadarTune does not depend on.",
        "",
    ]
    for model, m in e["models"].items():
        for imp in m["importance"]:
            top = sorted(imp["values"].items(), key=lambda kv: -kv[1])[:4]
            lines.append(f"- {model.upper()}, study `{imp['study']}` ({imp['n_trials']} trials): "
                         + ", ".join(f"{parameter(n).symbol} {v:.2f}" for n, v in top))  # fmt: skip
        for sk in m["importance_skipped"]:
            lines.append(f"- {model.upper()}, study `{sk['study']}`: no importance "
                         f"({sk['reason']})")  # fmt: skip
    for p in e.get("plots", []):
        if p.startswith("importance_"):
            lines += ["", f"![{p}]({p})"]
    if any("oat" in m for m in e["models"].values()):
        lines += [
            "",
            "### One parameter at a time",
            "",
            "The chosen parameters with one parameter swept across its bounds of eq. (15) (evenly "
            "in its sampling scale, plus the optimum's value), the others fixed; the paper's L_t "
            "and the capped loss on the chosen study's training set and on the held-out set, each "
            "divided by its value at the optimum. Range of L_t over each sweep (×10⁻³):",
            "",
            "| model | parameter | optimum | training: L_t at optimum | min | max | "
            "held-out: L_t at optimum | min | max |",
            "|---|---|---|---|---|---|---|---|---|",
        ]
        for model, m in e["models"].items():
            oat = m.get("oat")
            if not oat:
                continue
            for name, s in oat["training"].items():
                cells = []
                for label in ("training", "held-out"):
                    if label not in oat:
                        cells += ["–", "–", "–"]
                        continue
                    t = oat[label][name]
                    loss = np.array(t["loss"]) * 1e3
                    cells += [_f(loss[t["optimum_index"]], ".4f"), _f(loss.min(), ".4f"),
                              _f(loss.max(), ".4f")]  # fmt: skip
                opt = s["values"][s["optimum_index"]]
                lines.append(f"| {model.upper()} | {parameter(name).symbol} | {opt:.4g} | "
                             + " | ".join(cells) + " |")  # fmt: skip
        for model, m in e["models"].items():
            if "oat" in m:
                lines.append("")
                lines.append(f"- {model.upper()}: study `{m['study']}`, trial {m['trial']} "
                             f"(chosen by {m['chosen_by']}; its value in the study "
                             f"{m['value_in_study'] * 1e3:.4f} ×10⁻³, objective "
                             f"{m['loss']})")  # fmt: skip
        for p in e.get("plots", []):
            if p.startswith("sensitivity_"):
                lines += ["", f"![{p}]({p})"]
    if any("clutter" in m for m in e["models"].values()):
        lines += [
            "",
            "### Clutter robustness",
            "",
            "The chosen parameters re-tracked with the tracker's clutter density ρ scaled "
            "(ρ ×1 is the parameters as tuned), on the training and held-out sets and on the "
            "same sets simulated with the scene clutter rate λ (the paper's 0.02 m⁻²) scaled. "
            "L_t and the median trajectory loss ×10⁻³; confirmed: frames with a confirmed track; "
            "never: trajectories never confirmed.",
            "",
            "| model | data set | λ (m⁻²) | ρ × | ρ | L_t | median L(k) | capped | confirmed | "
            "never |",
            "|---|---|---|---|---|---|---|---|---|---|",
        ]
        for model, m in e["models"].items():
            if "clutter" not in m:
                continue
            for row in m["clutter"]["rows"]:
                lines.append(
                    f"| {model.upper()} | {row['dataset']} | {_f(row['clutter_per_m2'], '.3g')} | "
                    f"{row['rho_factor']:g} | {row['clutter_density']:.4g} | "
                    f"{_f(_scaled(row['loss_total'], 1e3), '.4f')} | "
                    f"{_f(_scaled(row['median_loss'], 1e3), '.4f')} | "
                    f"{_f(_scaled(row['capped_total'], 1e3), '.3f')} | "
                    f"{_f(_scaled(row['confirmed_fraction'], 100.0), '.1f')} % | "
                    f"{row['n_never_confirmed']} / {row['n_trajectories']} |"
                )
    for n in e.get("notes", []):
        lines += ["", f"Note: {n}"]
    return lines


__all__ = [
    "LAMBDA_VARIANTS",
    "plot_importance",
    "plot_oat",
    "sensitivity_entry",
    "sensitivity_markdown",
]
