"""The incident particle's kinetic energy (the paper's Fig. 8)."""
from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pandas as pd

from ..analysis import measures, packing, tables
from .base import biggest_series, finished, new_figure, save, series_label

log = logging.getLogger(__name__)


def tracer_energy(results, out: Path):
    """The incident particle's kinetic energy (Fig. 8). Left: E_k/E_k0 against its gap to the
    nearest earlier particle or the floor, one tracer per charge (the lowest seed's) of the
    series with the most charges, the paper's figure. Right: E_k/E_k0 just before the first
    contact against q for every series with a charged tracer, mean +- sd over the seeds that
    followed one (tracer_energy_before_contact.csv has every tracer's value). The
    bed is taken from the final configuration (particles with smaller id, which arrived before
    the tracer: hit-and-stick keeps them where they were when the tracer came)."""
    runs = [r for r in finished(results)
            if r.get("tracer") and packing.dump_exists(Path(r["dir"]) / "tracer.dump")]
    if not runs:
        log.warning("figure tracer_energy: no run with a tracer particle")
        return None
    fig = new_figure(13.0, 4.2)
    ax, axq = fig.add_subplot(121), fig.add_subplot(122)
    key, byq = biggest_series(runs)
    frames = []
    for q, rs in byq.items():
        r = min(rs, key=lambda r: r["params"]["seed"])
        t = measures.tracer_approach(Path(r["dir"]), r)
        if t is None:
            continue
        gaps, eks, k = t
        line, = ax.plot(gaps[: k + 1], eks[: k + 1], label=f"q = {q:g} e0: E_k/E_k0 = "
                        f"{eks[k - 1]:.3f} before the first contact")
        ax.plot(gaps[k - 1], eks[k - 1], "o", color=line.get_color())
        frames.append(pd.DataFrame({"q": q, "seed": r["params"]["seed"], "gap_over_rp": gaps,
                                    "Ek_over_Ek0": eks}))
    ax.axvline(0, color="grey", ls="--", lw=0.8)
    ax.set_xscale("symlog", linthresh=0.1)
    ax.set_xlabel("gap to the nearest deposited particle or the floor / r_p")
    ax.set_ylabel("E_k / E_k0")
    ax.set_title(f"{series_label(key)}, one tracer per q", fontsize=9)
    ax.legend(fontsize=7)
    # right: every series, the value before the first contact over the seeds
    before = tables.runs_frame(runs)[[*tables.CASE, "seed"]]
    before["Ek_before_contact"] = [measures.load(r["dir"], r).get("Ek_before_contact", np.nan)
                                   for r in runs]
    before = before.dropna(subset=["Ek_before_contact"])
    for skey, g in before.groupby(list(tables.CASE[:3])):
        if not (g["q"] > 0).any():
            continue                     # a neutral case alone: no trend to draw
        m = g.groupby("q")["Ek_before_contact"].agg(["mean", "std", "count"]).reset_index()
        axq.errorbar(m["q"], m["mean"], yerr=m["std"].fillna(0.0), marker="o", capsize=3,
                     label=series_label(skey) + (f" (up to {m['count'].max()} tracers per q)"
                                                  if m["count"].max() > 1 else ""))
    axq.set_xscale("symlog", linthresh=30.0)    # the series' charges span 30-2000 e0
    axq.set_xlabel("q / e0")
    axq.set_ylabel("E_k / E_k0 before the first contact")
    axq.set_title("mean +- sd over the seeds that followed a tracer", fontsize=9)
    axq.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    before.to_csv(Path(out) / "tracer_energy_before_contact.csv", index=False)
    return save(fig, Path(out) / "tracer_energy.png", pd.concat(frames) if frames else None)
