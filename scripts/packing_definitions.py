"""phi and <Z> of finished depositions measured by the conventions the paper leaves open.

    /usr/bin/python3 scripts/packing_definitions.py SWEEP_DIR [NAME_PART]

SWEEP_DIR holds the run folders of a `granular-charged sweep` (each with final.dump and
forces.dump); finished runs (with result.json) whose folder name contains NAME_PART are used. Prints mean +- sd over the runs of: phi in the analysis slab and over the whole
bed (H_p = highest particle top, or 2<z>), <Z> in the slab (geometric, force-carrying, without
rattlers) and over all particles (with or without floor contacts). doc/reproduction.md."""
import glob, sys, statistics as st
import numpy as np
sys.path.insert(0, str(__import__('pathlib').Path(__file__).resolve().parents[1] / 'python'))
from granular_charged.analysis import measures, packing

rows = {}
part = sys.argv[2] if len(sys.argv) > 2 else ''
for d in sorted(glob.glob(f'{sys.argv[1].rstrip("/")}/*/')):
    if part not in d or not glob.glob(d + 'result.json'):
        continue
    snap = packing.read_dump(d + 'final.dump', last_only=True)
    rp = float(snap['radius'][0]); z = np.asarray(snap['z'])
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
    c = measures.conventions(snap, rp)      # the whole-bed measures have one home
    out = {
        'slab phi': packing.phi_slab(snap, zlo, zhi),
        'whole bed phi, H = highest top': c['phi_bed_top'],
        'whole bed phi, H = 2<z>': c['phi_bed_2z'],
        'whole bed phi, H = mean surface height': c['phi_bed_surface'],
        'slab <Z> geometric': Z_all[inslab].mean(),
        '<Z> all particles': c['Z_all'],
        '<Z> all, floor contacts counted': c['Z_all_floor'],
        'slab <Z> force-carrying': Zf[inslab].mean(),
        'slab <Z> without rattlers (Z < 2)': Z_all[inslab & (Z_all >= 2)].mean(),
    }
    for k, v in out.items():
        rows.setdefault(k, []).append(v)
for k, v in rows.items():
    sd = st.stdev(v) if len(v) > 1 else float('nan')
    print(f"| {k} | {st.mean(v):.4f} +- {sd:.4f} |")
