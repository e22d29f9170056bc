"""phi and <Z> of finished depositions measured by the conventions the paper leaves open.

    /usr/bin/python3 scripts/packing_definitions.py SWEEP_DIR [NAME_PART]

SWEEP_DIR holds the run folders of a `granular-charged sweep` (each with final.dump and
forces.dump); finished runs (with result.json) whose folder name contains NAME_PART are used. Prints mean +- sd over the runs of: phi in the analysis slab and over the whole
bed (H_p = highest particle top, or 2<z>), <Z> in the slab (geometric, force-carrying, without
rattlers) and over all particles (with or without floor contacts). doc/reproduction.md."""
import glob, sys, statistics as st
import numpy as np
sys.path.insert(0, str(__import__('pathlib').Path(__file__).resolve().parents[1] / 'python'))
from granular_charged import packing

rows = {}
part = sys.argv[2] if len(sys.argv) > 2 else ''
for d in sorted(glob.glob(f'{sys.argv[1].rstrip("/")}/*/')):
    if part not in d or not glob.glob(d + 'result.json'):
        continue
    snap = packing.read_dump(d + 'final.dump', last_only=True)
    rp = float(snap['radius'][0]); z = np.asarray(snap['z']); r = np.asarray(snap['radius'])
    L = snap.box[0][1] - snap.box[0][0] if hasattr(snap, 'box') else None
    Lx, Ly = snap.lx, snap.ly
    vol = (4 / 3 * np.pi * r**3).sum()
    zlo, zhi = packing.analysis_slab(snap, rp)
    Z_all = packing.coordination(snap)
    inslab = (z >= zlo) & (z <= zhi)
    # force-carrying contacts: pairs with a nonzero normal force in forces.dump (ids, dist, F)
    f = np.loadtxt(d + 'forces.dump', skiprows=9)
    carry = np.zeros(int(snap['id'].max()) + 1)
    for a, b, dist, fn in f:
        if fn != 0.0:
            carry[int(a)] += 1; carry[int(b)] += 1
    ids = np.asarray(snap['id']).astype(int)
    Zf = carry[ids]
    floor = z - r < 1e-3 * rp          # touching the floor wall
    out = {
        'slab phi': packing.phi_slab(snap, zlo, zhi),
        'whole bed phi, H = highest top': vol / (Lx * Ly * (z + r).max()),
        'whole bed phi, H = 2<z>': vol / (Lx * Ly * 2 * z.mean()),
        # an area-independent height: the mean over columns of 2 r_p x 2 r_p of the top sphere
        'whole bed phi, H = mean surface height': vol / (Lx * Ly * np.nanmean(
            packing.surface_heights(snap, 2 * rp))),
        'slab <Z> geometric': Z_all[inslab].mean(),
        '<Z> all particles': Z_all.mean(),
        '<Z> all, floor contacts counted': (Z_all + floor).mean(),
        'slab <Z> force-carrying': Zf[inslab].mean(),
        'slab <Z> without rattlers (Z < 2)': Z_all[inslab & (Z_all >= 2)].mean(),
    }
    for k, v in out.items():
        rows.setdefault(k, []).append(v)
for k, v in rows.items():
    sd = st.stdev(v) if len(v) > 1 else float('nan')
    print(f"| {k} | {st.mean(v):.4f} +- {sd:.4f} |")
