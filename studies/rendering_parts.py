"""Where the rendering's error lies: a case assessed with the simulator's own views put into chosen parts of
the rendering, and how far each view's rendering lies across the track from the truth.

Each call of the renderer is made once: the service's rendering
(:func:`monitor.collocation.render.rendered_met`: the rendering with what each ray met,
:class:`~monitor.collocation.render.Met`), the simulator's views of the same GEO points
(:class:`studies.ideal_views.IdealViews`) and VIIRS's own BT are kept in the cache directory, keyed by the
call's inputs. Then, for each *part*, the rendering is given the simulator's view there and the
case is assessed on the rendered collocation at the fixed lift given (``parallax=False`` on it, as
``studies.ideal_views`` assesses the ideal views): what the offsets would be if the renderer were
right in that part alone. Parts:

- ``rendered``, ``ideal``: none, all;
- ``view:J``: the view of index J of :data:`~monitor.collocation.render.VIEW_ALPHA_RAD`;
- ``sixths:A-B``: the scan's sixths A to B by column (0 the first columns);
- ``detectors:A-B``: the detectors A to B of every scan;
- ``met:NAMES`` and ``not-met:NAMES``: where each ray met (or did not meet) one of the ``+``-joined
  :class:`~monitor.collocation.render.Met` names, lower case (``met:wall``, ``not-met:wall``).

With ``--shifts`` the row also holds each view's shift across the track, in columns, in each twelfth of the
scan: the rendered (and the simulator's) BT minus VIIRS's own, regressed on VIIRS's BT change per column,
over every cached call.

    .venv/bin/python -m studies.rendering_parts CASE_DIR --lift M_PER_K --cache DIR PART... [--shifts]
        [--rows FILE]

The simulator's views are traced once per call (~15 min for a 6-granule case on two cores); every part
after that is an assessment (~30 s).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import threading
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from benchmarks.provenance import emit
from monitor.assessment.estimates import cost_and_offsets, paired
from monitor.collocation import render
from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import VIIRS_DETECTORS
from studies.collocated import collocated
from studies.ideal_views import RENDERED_BT, IdealViews, simulator_of
from studies.lift_decision import case_fields, scores

TWELFTHS = 12


class Parts:
    """A renderer (:class:`monitor.collocation.render.Renderer`) that gives the simulator's views in one
    *part* (module docstring) and the service's rendering elsewhere, from the cache *cache* (made on first
    use)."""

    def __init__(self, truth: dict, cache: Path) -> None:
        self.cache = cache
        self.cache.mkdir(parents=True, exist_ok=True)
        self.ideal = IdealViews(simulator_of(truth))
        self.lock = threading.Lock()  # the ideal views draw their noise in call order
        self.part = "rendered"

    def _arrays(self, *args: object, **kwargs: object) -> dict[str, np.ndarray]:
        """The call's rendering, what its rays met, the simulator's views and VIIRS's BT, cached."""
        a = RENDERED_BT.bind(*args, **kwargs)
        a.apply_defaults()
        h = hashlib.sha1()
        for k in ("lat_rad", "bt_k"):
            h.update(np.ascontiguousarray(np.asarray(a.arguments[k])[::7, ::13]).tobytes())
        h.update(repr((a.arguments["scans"], a.arguments["columns"], float(a.arguments["m_per_k"]))).encode())
        files = {name: self.cache / f"{h.hexdigest()[:16]}_{name}.npy" for name in ("r", "kind", "i", "b")}
        if not files["r"].exists():
            rendered, met = render.rendered_met(*a.args, **a.kwargs)
            np.save(files["r"], rendered)
            np.save(files["kind"], met)
        if not files["b"].exists():
            np.save(files["b"], np.asarray(a.arguments["bt_k"], np.float32))
        if not files["i"].exists():
            with self.lock:
                np.save(files["i"], self.ideal(*a.args, **a.kwargs))
        return {name: np.load(f) for name, f in files.items()}

    def __call__(self, *args: object, **kwargs: object) -> np.ndarray:
        got = self._arrays(*args, **kwargs)
        out, truth = got["r"], got["i"]
        where = selected(self.part, got["kind"])
        where &= np.isfinite(truth)
        out[where] = truth[where]
        return out


def selected(part: str, met: np.ndarray) -> np.ndarray:
    """Where *part* (module docstring) takes the simulator's view, for a rendering of shape ``met.shape``
    whose rays met *met*."""
    views, rows, cols = met.shape
    kind, _, arg = part.partition(":")
    where = np.zeros(met.shape, bool)
    if kind in ("view", "sixths", "detectors", "met", "not-met") and not arg:
        raise ValueError(f"rendering_parts: part {part!r} needs its argument after ':'")
    if kind == "ideal":
        where[:] = True
    elif kind == "view":
        where[int(arg)] = True
    elif kind in ("sixths", "detectors"):
        lo, hi = (int(v) for v in arg.split("-"))
        if kind == "sixths":
            sixth = np.arange(cols) * 6 // cols
            where[:, :, (sixth >= lo) & (sixth <= hi)] = True
        else:
            detector = np.arange(rows) % VIIRS_DETECTORS
            where[:, (detector >= lo) & (detector <= hi), :] = True
    elif kind in ("met", "not-met"):
        for name in arg.split("+"):
            if name.upper() not in render.Met.__members__:
                raise ValueError(f"rendering_parts: part {part!r}: {name!r} is no Met name")
            where |= met == render.Met[name.upper()]
        if kind == "not-met":
            where = ~where & (met != render.Met.NOTHING)
    elif kind != "rendered":
        raise ValueError(f"rendering_parts: part {part!r} is none of the module docstring's")
    return where


def shifts(cache: Path) -> dict[str, list[list[float]]]:
    """Each view's shift across the track (columns) in each twelfth of the scan, rendered and simulated,
    against VIIRS's own BT (module docstring), over every call in *cache*."""
    sums: dict[str, np.ndarray] = {}
    for file in sorted(cache.glob("*_r.npy")):
        viirs = np.load(str(file).replace("_r.npy", "_b.npy")).astype(np.float64)
        per_column = np.full_like(viirs, np.nan)
        per_column[:, 1:-1] = (viirs[:, 2:] - viirs[:, :-2]) / 2
        twelfth = np.arange(viirs.shape[1]) * TWELFTHS // viirs.shape[1]
        for name, suffix in (("rendered", "_r.npy"), ("ideal", "_i.npy")):
            views = np.load(str(file).replace("_r.npy", suffix))
            acc = sums.setdefault(name, np.zeros((len(views), TWELFTHS, 2)))
            for v, seen in enumerate(views):
                e = seen.astype(np.float64) - viirs
                ok = np.isfinite(e) & np.isfinite(per_column)
                for t in range(TWELFTHS):
                    m = ok & (twelfth == t)[None, :]
                    acc[v, t] += (np.sum(e[m] * per_column[m]), np.sum(per_column[m] ** 2))
    return {name: np.round(acc[..., 0] / acc[..., 1], 3).tolist() for name, acc in sums.items()}


def measure(case: Path, lift_m_per_k: float, cache: Path, parts: list[str], workers: int) -> Iterator[dict]:
    """One row per part of *case* assessed at *lift_m_per_k* (module docstring), as each is assessed."""
    truth = json.loads((case / "truth.json").read_text())
    cfg = AssessmentConfig(workers=workers)
    plain = cfg.model_copy(update={"parallax": False})
    renderer = Parts(truth, cache)
    for part in parts:  # a typo fails before the first trace
        selected(part, np.zeros((len(render.VIEW_ALPHA_RAD), VIIRS_DETECTORS, 6), np.uint8))
    for part in parts:
        renderer.part = part
        samples = collocated(case, cfg, workers, lift_m_per_k, renderer=renderer)
        result = cost_and_offsets(paired(samples)[1], plain, satellite=truth["satellite"])
        yield {**case_fields(case, truth), "granules": truth["granules"], "lift_m_per_k": lift_m_per_k,
               "part": part, "scores": scores(result, truth)}  # fmt: skip


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("case", type=Path)
    p.add_argument("parts", nargs="+")
    p.add_argument("--lift", type=float, required=True, help="the rendering's lift, m/K")
    p.add_argument("--cache", type=Path, required=True, help="where each call's arrays are kept")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--shifts", action="store_true", help="also each view's shift across the track")
    p.add_argument("--rows", help="append the JSON rows to this file")
    args = p.parse_args()
    for row in measure(args.case, args.lift, args.cache, args.parts, args.workers):
        emit(row, args.rows)
    if args.shifts:
        emit({**case_fields(args.case, json.loads((args.case / "truth.json").read_text())),
              "shift_columns": shifts(args.cache)}, args.rows)  # fmt: skip


if __name__ == "__main__":
    main()
