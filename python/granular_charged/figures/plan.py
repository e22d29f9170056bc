"""Which figures a result set gets (figure_tasks) and drawing them (all_figures): every
figure the runs allow, in one folder, PNG with the plotted data as CSV beside it. The drawing
itself is in the modules by subject. Functions take result dicts (``Runner.deposition`` /
``sweep.load_results``; each has ``dir``, the run folder) and an output folder and return the
PNG path, or None when the runs needed are missing (the reason is logged)."""
from __future__ import annotations

import logging
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from .adhesion import vs_adstar
from .base import PAPER, biggest_series, finished, material_label
from .conventions import conventions
from .expansion import phi_vs_q, table2
from .forces import force_network, force_pdf
from .packings import packing_image, packing_image_names, packings_panel
from .structure import fZ, rdf
from .tracer import tracer_energy

log = logging.getLogger(__name__)


def all_figures(results, out: Path, table2_rows: list[dict] | None = None,
                table2_dir: Path | None = None, jobs: int = 1,
                paper_notes: bool | None = None) -> list[Path]:
    """Every figure the given runs allow; returns the PNG paths written. jobs > 1: drawn by
    that many processes (each figure is independent of the others). paper_notes: draw the
    paper's values and annotations (None: when the runs are of the paper's material with one
    kind of particle); otherwise the series are labelled with the runs' material."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    results = [r for r in results if r.get("complete")]
    if not results:
        log.warning("figures: no finished runs")
        return []
    mat = material_label(results)
    PAPER["on"] = (not mat) if paper_notes is None else paper_notes
    PAPER["material"] = mat
    tasks = figure_tasks(results, out, table2_rows)
    if jobs > 1 and len(tasks) > 1:
        # fork: the workers start at once with this process's modules (no re-import)
        with ProcessPoolExecutor(jobs, mp_context=multiprocessing.get_context("fork")) as ex:
            drawn = list(ex.map(_draw, tasks))
    else:
        drawn = [_draw(t) for t in tasks]
    paths = [q for d in drawn for q in (d if isinstance(d, (tuple, list)) else (d,))]
    return [q for q in paths if q is not None]


def _draw(task):
    fn, args = task
    return fn(*args)


def figure_tasks(results, out: Path, table2_rows: list[dict] | None) -> list[tuple]:
    """The figures of all_figures as (function, arguments), in the order of their paths."""
    tasks = []
    ok = finished(results)
    for r, name in zip(ok, packing_image_names(ok)):
        tasks.append((packing_image, (r, out, name)))
    tasks += [(packings_panel, (results, out)), (phi_vs_q, (results, out)),
              (rdf, (results, out)), (fZ, (results, out)), (tracer_energy, (results, out)),
              (conventions, (results, out)), (vs_adstar, (results, out))]
    if ok:
        key, byq = biggest_series(ok)
        qs = list(byq)
        picks = [byq[qs[0]][0]] + ([byq[qs[-1]][0]] if len(qs) > 1 else [])
        params = picks[0]["params"]
        tasks.append((force_network, (
            [(f"deposited with q = {r['params']['q']:g} e0", Path(r["dir"]) / "final.dump",
              Path(r["dir"]) / "forces.dump") for r in picks], params, out,
            "force_network_deposition.png")))
        tasks.append((force_pdf, ([(f"deposited with q = {q:g} e0", Path(r["dir"]) / "forces.dump")
                                   for q in qs for r in byq[q][:1]], params, out)))
    if table2_rows:
        tasks.append((table2, (table2_rows, out)))
        # the paper's Figs. 6 and 7 proper: the Table 2 packing before and after charging (of
        # the first seed when several packings were checked)
        first = min((r.get("params") or {}).get("seed", 0) for r in table2_rows)
        last = max((r for r in table2_rows if (r.get("params") or {}).get("seed", 0) == first),
                   key=lambda r: r["q"])
        d = Path(last["dir"])
        params = last["params"]
        tasks.append((force_network, (
            [("neutral packing (formed with q = 0)", d / "before.dump", d / "forces_before.dump"),
             (f"after charging to q = {last['q']:g} e0 and relaxing", d / "after.dump",
              d / "forces_after.dump")], params, out, "force_network.png")))
        tasks.append((force_pdf, ([("neutral packing", d / "forces_before.dump"),
                                   (f"charged after formation, q = {last['q']:g} e0",
                                    d / "forces_after.dump")], params, out,
                                  "force_pdf_table2.png")))
    return tasks
