"""Packing analysis from LAMMPS dumps: volume fraction of a slab (exact sphere-slab volumes),
geometric contacts and coordination numbers, f(Z), g(r) of a slab, phi(z) profile, bed surface.

The box is periodic in x and y and open in z (the decks' ``boundary p p f``). These functions
are the Python reference for the package's computes ``packing/slab``, ``coord/dist`` and
``rdf/slab``; python/tests cross-checks them against the computes when those are built.
"""
from __future__ import annotations

import gzip
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass
class Snapshot:
    step: int
    box: np.ndarray          # [[xlo, xhi], [ylo, yhi], [zlo, zhi]]
    cols: dict               # column name -> np.ndarray, sorted by id when 'id' exists

    def __getitem__(self, k):
        return self.cols[k]

    @property
    def n(self) -> int:
        return len(next(iter(self.cols.values()))) if self.cols else 0

    @property
    def xyz(self) -> np.ndarray:
        return np.column_stack([self.cols["x"], self.cols["y"], self.cols["z"]])

    @property
    def lx(self) -> float:
        return float(self.box[0, 1] - self.box[0, 0])

    @property
    def ly(self) -> float:
        return float(self.box[1, 1] - self.box[1, 0])


def read_text(path) -> str:
    """A text file, or its gzip-compressed copy path.gz when path itself is absent (the run
    folders kept in the repository are compressed, doc/data/README.md)."""
    path = Path(path)
    if not path.exists() and path.with_name(path.name + ".gz").exists():
        with gzip.open(path.with_name(path.name + ".gz"), "rt") as fh:
            return fh.read()
    return path.read_text()


def dump_exists(path) -> bool:
    """The dump or its compressed copy (read_text) is there."""
    path = Path(path)
    return path.exists() or path.with_name(path.name + ".gz").exists()


def read_dump(path, last_only=False):
    """Read a LAMMPS text dump (custom or local; path or path.gz, read_text). Returns a list of
    Snapshot (or the last)."""
    snaps = []
    lines = read_text(path).split("\n")
    i, n = 0, len(lines)
    while i < n:
        if not lines[i].startswith("ITEM: TIMESTEP"):
            i += 1
            continue
        step = int(lines[i + 1])
        i += 2
        nrows = None
        box = np.zeros((3, 2))
        cols = {}
        while i < n and lines[i].startswith("ITEM:"):
            item = lines[i]
            if item.startswith("ITEM: NUMBER OF"):
                nrows = int(lines[i + 1])
                i += 2
            elif item.startswith("ITEM: BOX BOUNDS"):
                for d in range(3):
                    box[d] = [float(v) for v in lines[i + 1 + d].split()[:2]]
                i += 4
            elif item.startswith("ITEM: ATOMS") or item.startswith("ITEM: ENTRIES"):
                names = item.split()[2:]
                data = np.array([lines[i + 1 + k].split() for k in range(nrows)], dtype=float)
                data = data.reshape(nrows, len(names))
                cols = {nm: data[:, c] for c, nm in enumerate(names)}
                if "id" in cols:
                    order = np.argsort(cols["id"])
                    cols = {k: v[order] for k, v in cols.items()}
                    cols["id"] = cols["id"].astype(int)
                i += 1 + nrows
                break
            else:
                i += 1
        snaps.append(Snapshot(step, box, cols))
    if last_only:
        return snaps[-1] if snaps else None
    return snaps


# ---- volume fraction ------------------------------------------------------------------------

def sphere_slab_volume(zc, r, zlo, zhi):
    """Exact volume of spheres (centres zc, radii r) between the planes z = zlo and z = zhi:
    int_{max(zlo, zc - r)}^{min(zhi, zc + r)} pi (r^2 - (s - zc)^2) ds. Vectorised."""
    zc = np.asarray(zc, dtype=float)
    r = np.asarray(r, dtype=float)
    zc, r, zlo, zhi = np.broadcast_arrays(zc, r, np.asarray(zlo, float), np.asarray(zhi, float))
    u1 = np.clip(zlo - zc, -r, r)
    u2 = np.clip(zhi - zc, -r, r)
    F = lambda u: math.pi * (r * r * u - u ** 3 / 3.0)
    return np.maximum(F(u2) - F(u1), 0.0)


def phi_slab(snap: Snapshot, zlo: float, zhi: float) -> float:
    """Volume fraction of the bed between zlo and zhi (periodic x, y)."""
    v = sphere_slab_volume(snap["z"], snap["radius"], zlo, zhi).sum()
    return float(v / (snap.lx * snap.ly * (zhi - zlo)))


def phi_profile(snap: Snapshot, dz: float, zmax: float | None = None):
    """phi(z) in bins of width dz from z = 0: returns (bin centres, phi).

    Vectorised: the sphere volume below each bin edge, V(z_k) = sum_i vol_i(-inf, z_k), is one
    (N x bins) array; the volume in bin k is V(z_{k+1}) - V(z_k), so each sphere's volume is
    split exactly between the bins it crosses."""
    zmax = zmax if zmax is not None else float(np.max(snap["z"] + snap["radius"]))
    edges = np.arange(0.0, zmax + dz, dz)
    below = sphere_slab_volume(snap["z"][:, None], snap["radius"][:, None], -np.inf,
                               edges[None, :]).sum(axis=0)
    phi = np.diff(below) / (snap.lx * snap.ly * np.diff(edges))
    return 0.5 * (edges[:-1] + edges[1:]), phi


def analysis_slab(snap: Snapshot, rp: float, zlo_rp: float = 4.0, top_rp: float = 6.0):
    """The decks' analysis region: zlo = zlo_rp r_p (excludes the floor layer),
    zhi = 2 <z> - top_rp r_p (2 <z> is the height of a uniform bed with the same centroid;
    top_rp r_p below it excludes the rough top). Same rule as in.deposition."""
    zlo = zlo_rp * rp
    zhi = 2.0 * float(np.mean(snap["z"])) - top_rp * rp
    return zlo, zhi


def surface_heights(snap: Snapshot, cell: float):
    """Highest sphere top (z + r) in each column of a cell x cell grid (nan where empty),
    shape (nx, ny); vectorised with an unbuffered maximum (np.fmax.at)."""
    nx = max(1, int(round(snap.lx / cell)))
    ny = max(1, int(round(snap.ly / cell)))
    ix = np.floor((snap["x"] - snap.box[0, 0]) / snap.lx * nx).astype(int) % nx
    iy = np.floor((snap["y"] - snap.box[1, 0]) / snap.ly * ny).astype(int) % ny
    top = np.full(nx * ny, -np.inf)
    np.fmax.at(top, ix * ny + iy, snap["z"] + snap["radius"])
    top[np.isneginf(top)] = np.nan
    return top.reshape(nx, ny)


# ---- contacts -------------------------------------------------------------------------------

def periodic_tree(snap: Snapshot, rcut: float):
    """cKDTree of the centres with the box's periodicity: x, y wrap with the box lengths; the
    open z axis is shifted to start at 0 and given a period longer than the bed's height plus
    2 rcut, so no pair closer than rcut is ever found through a z "image". Returns
    (tree, wrapped coordinates)."""
    # scipy.spatial takes ~0.15 s to load: here, so that the command line starts without it
    from scipy.spatial import cKDTree

    xyz = snap.xyz.copy()
    xyz[:, 0] = np.mod(xyz[:, 0] - snap.box[0, 0], snap.lx)
    xyz[:, 1] = np.mod(xyz[:, 1] - snap.box[1, 0], snap.ly)
    # np.mod can return exactly L for -tiny inputs; cKDTree needs 0 <= x < boxsize
    xyz[:, 0] = np.where(xyz[:, 0] >= snap.lx, 0.0, xyz[:, 0])
    xyz[:, 1] = np.where(xyz[:, 1] >= snap.ly, 0.0, xyz[:, 1])
    xyz[:, 2] -= xyz[:, 2].min() if len(xyz) else 0.0
    bz = (xyz[:, 2].max() if len(xyz) else 0.0) + 2.0 * rcut + 1.0 * max(snap.lx, snap.ly)
    return cKDTree(xyz, boxsize=[snap.lx, snap.ly, bz]), xyz


def pair_vectors(snap: Snapshot, rcut: float):
    """All pairs (i < j, indices into the snapshot) with r_ij <= rcut, with their separations
    r_i - r_j (x, y periodic by the minimum image, z open; one row per pair)."""
    tree, xyz = periodic_tree(snap, rcut)
    pairs = tree.query_pairs(rcut, output_type="ndarray")
    if len(pairs) == 0:
        return pairs.reshape(0, 2), np.zeros((0, 3))
    d = xyz[pairs[:, 0]] - xyz[pairs[:, 1]]
    d[:, 0] -= snap.lx * np.round(d[:, 0] / snap.lx)
    d[:, 1] -= snap.ly * np.round(d[:, 1] / snap.ly)
    return pairs, d


def pair_distances(snap: Snapshot, rcut: float):
    """All pairs (i < j) with r_ij <= rcut, with distances (pair_vectors)."""
    pairs, d = pair_vectors(snap, rcut)
    return pairs, np.sqrt((d * d).sum(axis=1))


def contacts(snap: Snapshot, tol: float = 0.0):
    """Geometric contacts, the definition of LAMMPS ``compute coord/dist contact geometric``
    (doc/compute_coord_dist.rst): r_ij <= r_i + r_j + tol (tol = 0: touching or overlapping, the
    paper's 'geometrical contact'). Returns (pairs, overlaps delta = r_i + r_j - r_ij)."""
    rad = snap["radius"]
    pairs, dist = pair_distances(snap, 2.0 * rad.max() + tol)
    if len(pairs) == 0:
        return pairs, dist
    ov = rad[pairs[:, 0]] + rad[pairs[:, 1]] - dist
    keep = ov >= -tol
    return pairs[keep], ov[keep]


def contact_normals(snap: Snapshot, tol: float = 0.0):
    """The geometric contacts of contacts() with unit vectors along them (from j to i; the sign
    carries no meaning): (pairs, normals), one row per contact."""
    rad = snap["radius"]
    pairs, d = pair_vectors(snap, 2.0 * rad.max() + tol)
    if len(pairs) == 0:
        return pairs, d
    dist = np.sqrt((d * d).sum(axis=1))
    keep = rad[pairs[:, 0]] + rad[pairs[:, 1]] - dist >= -tol
    return pairs[keep], d[keep] / dist[keep, None]


def coordination(snap: Snapshot, tol: float = 0.0) -> np.ndarray:
    """Per-particle number of particle-particle contacts (the floor is not counted)."""
    pairs, _ = contacts(snap, tol)
    Z = np.zeros(snap.n, dtype=int)
    np.add.at(Z, pairs[:, 0], 1)
    np.add.at(Z, pairs[:, 1], 1)
    return Z


ZMAX_DEFAULT = 20   # compute coord/dist's default zmax


def fz_histogram(Z, zmax: int = ZMAX_DEFAULT) -> np.ndarray:
    """f(Z) as compute coord/dist defines it: zmax + 1 bins Z = 0 .. zmax, the last one counting
    every Z >= zmax (so f sums to 1 whatever the largest Z); fractions of len(Z)."""
    Z = np.asarray(Z, dtype=int)
    f = np.bincount(np.minimum(Z, zmax), minlength=zmax + 1).astype(float)
    return f / max(len(Z), 1)


def coordination_stats(snap: Snapshot, zlo: float, zhi: float, tol: float = 0.0,
                       zmax: int = ZMAX_DEFAULT):
    """<Z> and f(Z) over the particles whose centres lie in [zlo, zhi], with the definitions of
    ``compute coord/dist z zlo zhi contact geometric tolerance tol zmax zmax``: contacts by
    :func:`contacts`, f(Z) by :func:`fz_histogram` (Z >= zmax in the last bin), <Z> from the
    true Z."""
    Z = coordination(snap, tol)
    sel = (snap["z"] >= zlo) & (snap["z"] <= zhi)
    Zs = Z[sel]
    f = fz_histogram(Zs, zmax)
    return {"Z": float(Zs.mean()) if len(Zs) else float("nan"), "fZ": f.tolist(),
            "n_slab": int(sel.sum()), "Z_all": Z}


def rdf_slab(snap: Snapshot, zlo: float, zhi: float, rmax: float, nbins: int = 200):
    """g(r) of the particles with centres in [zlo, zhi] (both members of a pair in the slab),
    normalised for the slab: the ideal count for reference i in the shell [r, r + dr] is
    rho_s * 2 pi r * |[z_i - r, z_i + r] n [zlo, zhi]| * dr (area of a spherical zone), with
    rho_s = N_s / (L_x L_y (zhi - zlo)); x, y periodic. Returns (r centres, g)."""
    sel = np.flatnonzero((snap["z"] >= zlo) & (snap["z"] <= zhi))
    sub = Snapshot(snap.step, snap.box, {k: v[sel] for k, v in snap.cols.items()})
    pairs, dist = pair_distances(sub, rmax)
    edges = np.linspace(0.0, rmax, nbins + 1)
    counts = np.histogram(dist, bins=edges)[0] * 2.0
    rc = 0.5 * (edges[:-1] + edges[1:])
    dr = edges[1] - edges[0]
    rho_s = len(sel) / (snap.lx * snap.ly * (zhi - zlo))
    z = sub["z"][:, None]
    overlap = np.clip(np.minimum(z + rc, zhi) - np.maximum(z - rc, zlo), 0.0, None)
    ideal = rho_s * 2.0 * math.pi * rc * overlap.sum(axis=0) * dr
    g = np.where(ideal > 0, counts / np.where(ideal > 0, ideal, 1.0), 0.0)
    return rc, g


def analyse(snap: Snapshot, rp: float, zlo_rp=4.0, top_rp=6.0, tol=0.0,
            zmax: int = ZMAX_DEFAULT) -> dict:
    """phi, <Z>, f(Z) (zmax + 1 bins) of the analysis slab of a final snapshot (the decks'
    rule)."""
    zlo, zhi = analysis_slab(snap, rp, zlo_rp, top_rp)
    out = {"zlo": zlo, "zhi": zhi, "slab_thickness_rp": (zhi - zlo) / rp}
    if zhi <= zlo:      # in.deposition's rule (slab_ok): a slab exists when zhi > zlo
        out.update({"phi": float("nan"), "Z": float("nan"), "fZ": [], "n_slab": 0,
                    "warning": "bed too thin for the analysis slab"})
        return out
    out["phi"] = phi_slab(snap, zlo, zhi)
    cs = coordination_stats(snap, zlo, zhi, tol, zmax)
    out.update({k: cs[k] for k in ("Z", "fZ", "n_slab")})
    return out


# ---- mixtures and size spreads --------------------------------------------------------------

def size_classes(radii: np.ndarray, nclass: int = 4) -> np.ndarray:
    """Class edges of a set of radii: each distinct radius when there are at most 6 (a discrete
    population), else nclass classes of equal numbers (quantiles)."""
    u = np.unique(radii)
    if len(u) <= 6:
        mid = 0.5 * (u[1:] + u[:-1])
        return np.concatenate([[u[0] * 0.999], mid, [u[-1] * 1.001]])
    e = np.quantile(radii, np.linspace(0.0, 1.0, nclass + 1))
    e[0] *= 0.999
    e[-1] *= 1.001
    return e


def by_class(snap: Snapshot, population: dict | None, zlo: float, zhi: float, tol: float = 0.0,
             zmax: int = ZMAX_DEFAULT) -> dict:
    """<Z> and f(Z) of the slab's particles per species (the dump's type) and per size class
    (size_classes of each species' radii in the slab), and the mean diameter of the slab:
    {'mean_diameter', 'classes': [{'species', 'r_lo', 'r_hi', 'n', 'Z', 'fZ'}, ...]}."""
    if zhi <= zlo:
        return {"classes": []}
    Z = coordination(snap, tol)
    sel = (snap["z"] >= zlo) & (snap["z"] <= zhi)
    types = snap["type"].astype(int) if "type" in snap.cols else np.ones(snap.n, dtype=int)
    rad = snap["radius"]
    rows = []
    for t in np.unique(types[sel]):
        st = sel & (types == t)
        rows.append({"species": int(t), "r_lo": float(rad[st].min()), "r_hi": float(rad[st].max()),
                     "n": int(st.sum()), "Z": float(Z[st].mean()),
                     "fZ": fz_histogram(Z[st], zmax).tolist(), "class": "all"})
        edges = size_classes(rad[st])
        for k in range(len(edges) - 1):
            sk = st & (rad >= edges[k]) & (rad < edges[k + 1])
            if sk.any():
                rows.append({"species": int(t), "r_lo": float(rad[sk].min()),
                             "r_hi": float(rad[sk].max()), "n": int(sk.sum()),
                             "Z": float(Z[sk].mean()), "fZ": fz_histogram(Z[sk], zmax).tolist(),
                             "class": k + 1})
    return {"mean_diameter": float(2.0 * rad[sel].mean()) if sel.any() else float("nan"),
            "classes": rows}


def rdf_contact(snap: Snapshot, zlo: float, zhi: float, xmax: float = 3.0, nbins: int = 150,
                partners: int = 256, seed: int = 0):
    """g as a function of x = r_ij / (r_i + r_j) (contact at x = 1 for every pair) of the
    particles with centres in [zlo, zhi]: pair counts in bins of x over the ideal-gas count of the
    same slab, for which a reference i and a partner j at distance x (r_i + r_j) add
    rho_s 2 pi r |[z_i - r, z_i + r] n [zlo, zhi]| dr (rdf_slab's zone), averaged over the
    partners' radii (a random subset of `partners`). A monodisperse packing gives rdf_slab with
    r = 2 r_p x. Returns (x centres, g)."""
    sel = np.flatnonzero((snap["z"] >= zlo) & (snap["z"] <= zhi))
    sub = Snapshot(snap.step, snap.box, {k: v[sel] for k, v in snap.cols.items()})
    rs = sub["radius"]
    pairs, dist = pair_distances(sub, xmax * 2.0 * rs.max())
    x = dist / (rs[pairs[:, 0]] + rs[pairs[:, 1]])
    edges = np.linspace(0.0, xmax, nbins + 1)
    counts = np.histogram(x, bins=edges)[0] * 2.0
    xc = 0.5 * (edges[:-1] + edges[1:])
    dx = edges[1] - edges[0]
    rho_s = len(sel) / (snap.lx * snap.ly * (zhi - zlo))
    rng = np.random.default_rng(seed)
    pj = rs if len(rs) <= partners else rng.choice(rs, partners, replace=False)
    sig = rs[:, None] + pj[None, :]
    z = sub["z"][:, None]
    ideal = np.empty(nbins)
    for k in range(nbins):
        r = xc[k] * sig
        ov = np.clip(np.minimum(z + r, zhi) - np.maximum(z - r, zlo), 0.0, None)
        ideal[k] = rho_s * (2.0 * math.pi * r * ov * dx * sig).mean(axis=1).sum()
    g = np.where(ideal > 0, counts / np.where(ideal > 0, ideal, 1.0), 0.0)
    return xc, g
