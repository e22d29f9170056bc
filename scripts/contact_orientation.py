"""The contact directions against the vertical (the EPD study's field axis) of any finished runs,
for comparison with the EPD study (doc/epd.md, "Results"): per case (the run key without its
seed) the order parameter S = <3 cos^2 theta - 1>/2 and <|cos theta|> of the contacts in the
deck's analysis slab, mean +- sd over the seeds.

    /usr/bin/python3 scripts/contact_orientation.py doc/data/paper-size/runs/rp2um_U1_g10mJ_q{0,400}_N2000_s[123]*
"""
from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))
from granular_charged.studies import epd  # noqa: E402
from granular_charged.analysis import tables  # noqa: E402


def main(dirs: list[str]) -> int:
    rows = []
    for d in map(Path, dirs):
        r = {**json.loads((d / "result.json").read_text()), "dir": str(d)}
        o = epd.contact_orientation_of_run(r)
        rows.append({"case": re.sub(r"_s\d+", "_s*", r["key"]), "seed": r["params"]["seed"],
                     "phi": r["phi"], "S": o["S"], "mean_abs_cos": o["mean_abs_cos"],
                     "contacts": o["contacts"]})
    if not rows:
        print(__doc__)
        return 1
    df = pd.DataFrame(rows)
    for case, g in df.groupby("case"):
        print(f"{case}: {len(g)} seeds, phi {tables.with_uncertainty(g['phi'].mean(), g['phi'].std())}, "
              f"S {tables.with_uncertainty(g['S'].mean(), g['S'].std())}, <|cos theta|> "
              f"{tables.with_uncertainty(g['mean_abs_cos'].mean(), g['mean_abs_cos'].std())}, "
              f"{g['contacts'].mean():.0f} contacts per run")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
