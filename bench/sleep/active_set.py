#!/usr/bin/python3
"""fix bury/gran's rule applied to dumps of a sleeping deposition: how many sleepers its cell
window keeps in the group `active`, and how many it would keep if the awake atoms that touch
no other atom and lie on the floor were asleep (they count no pair contact).

The dumps hold `id x y z radius f_sleep v_act` (v_act: atom-style variable gmask(active)); a
copy of the deck with them, every 500000 steps:

    awk '{print} /"variable sleep_thermo string f_sleep"/ {print "variable act atom gmask(active)";
         print "dump diag all custom 500000 ${out}/diag.*.dump id x y z radius f_sleep v_act"}' \\
        python/granular_charged/decks/in.deposition > in.diag
    lmp -in in.diag -var out OUT -var N 8000 -var L_rp 28 -var seed 1
    bench/sleep/active_set.py HALO_RP OUT/diag.*.dump

HALO_RP: fix bury/gran's halo in r_p (the deck's: max(2 r_max + skin, coul_near r_p) + 4 r_max + 2 skin,
6.75 for one size of particle). The cells are those of fix bury/gran: 2 r_max wide in x and y,
r_max / 2 tall, a window of ceil(halo / cell) cells each way.
"""
import sys
from pathlib import Path

import numpy as np
from scipy.ndimage import maximum_filter
from scipy.spatial import cKDTree

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from granular_charged.analysis.packing import read_dump  # noqa: E402


def main(argv):
    if len(argv) < 3:
        sys.exit(__doc__)
    halo_rp = float(argv[1])
    for path in argv[2:]:
        snap = read_dump(path, last_only=True)
        bounds, c = snap.box, snap.cols
        n = len(c['id'])
        rp = c['radius'].max()
        prd = bounds[:, 1] - bounds[:, 0]
        x = np.column_stack([c['x'], c['y'], c['z']]) - bounds[:, 0]
        x[:, :2] %= prd[:2]
        asleep, active = c['f_sleep'] != 0, c['v_act'] != 0
        side = 2 * rp
        ncell = np.maximum(1, (prd / np.array([side, side, 0.25 * side])).astype(int))
        width = prd / ncell
        k = np.maximum(1, np.ceil(halo_rp * rp / width).astype(int))
        cell = np.minimum((x / width).astype(int), ncell - 1)
        pairs = cKDTree(x, boxsize=[prd[0], prd[1], 1e3 * prd[2]]).query_pairs(
            2 * rp * 1.0001, output_type='ndarray')
        touches = np.zeros(n, bool)
        touches[pairs.ravel()] = True

        def kept(awake):
            grid = np.zeros(ncell, bool)
            c = cell[awake]
            grid[c[:, 0], c[:, 1], c[:, 2]] = True
            grid = maximum_filter(grid, size=tuple(2 * k + 1), mode=('wrap', 'wrap', 'constant'))
            c = cell[asleep]
            return int(grid[c[:, 0], c[:, 1], c[:, 2]].sum())

        awake = ~asleep
        loners = awake & ~touches & (x[:, 2] < 1.01 * rp)
        print(f'{path}: {n} atoms, {awake.sum()} awake, {active.sum()} in active '
              f'({(active & asleep).sum()} sleepers); window {k} cells; sleepers kept by the rule '
              f'{kept(awake)}, with the {loners.sum()} lone awake atoms on the floor asleep '
              f'{kept(awake & ~loners)}')


if __name__ == '__main__':
    main(sys.argv)
